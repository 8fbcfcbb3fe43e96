// render/pending_tables.cpp — see pending_tables.h.
#include "render/pending_tables.h"

#include <utility>

namespace vdbsplat {

PendingTables::PendingTables(std::filesystem::path dir, const KernelShape& kernel) : kernel_(kernel) {
    group_.run([this, dir = std::move(dir)] {
        try {
            tables_ = std::make_shared<const Tables>(loadOrBuildTables(dir, kernel_));
        } catch (...) {
            error_ = std::current_exception();
        }
    });
}

PendingTables::PendingTables(std::shared_ptr<const Tables> ready, const KernelShape& kernel)
    : kernel_(kernel), tables_(std::move(ready)), done_(true) {}

PendingTables::~PendingTables() {
    if (!done_) group_.wait();  // the task catches everything: wait() cannot throw its error
}

const std::shared_ptr<const Tables>& PendingTables::shared() {
    if (!done_) group_.wait(), done_ = true;
    if (error_) std::rethrow_exception(error_);
    return tables_;
}

}  // namespace vdbsplat
