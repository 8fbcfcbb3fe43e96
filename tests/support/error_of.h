// tests/support/error_of.h — shared by the test folders (header only, so CMake builds no
// test executable for this folder): the message of the vdbsplat::Error a call throws.
#pragma once
#include <gtest/gtest.h>

#include <string>

#include "util/error.h"

namespace vdbsplat::test {

/// @brief The message of the Error that @p fn throws; "" and a test failure when it throws none.
template <typename Fn>
std::string errorOf(Fn&& fn) {
    try {
        fn();
    } catch (const Error& e) {
        return e.what();
    }
    ADD_FAILURE() << "expected a vdbsplat::Error";
    return "";
}

}  // namespace vdbsplat::test
