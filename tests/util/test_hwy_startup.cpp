// tests/util/test_hwy_startup.cpp — util/hwy_startup.cpp: the executable's definition of
// hwy::platform::TimerResolution is the one the process resolves (libhwy's static initialiser
// calls it through the dynamic loader), and it answers without measuring.
#include <dlfcn.h>
#include <gtest/gtest.h>
#include <hwy/nanobenchmark.h>

#include "util/hwy_startup.h"

namespace vdbsplat {
namespace {

TEST(HwyStartup, TheExecutablesDefinitionAnswers) {
    // libhwy's own measures back-to-back timer reads; this binary's returns the fixed value.
    EXPECT_EQ(hwy::platform::TimerResolution(), kHwyTimerResolutionTicks);
}

TEST(HwyStartup, TheDynamicLoaderFindsTheExecutablesDefinition) {
    // What libhwy's call at load time binds to: the first definition in the global lookup
    // order. Without the executable's export (--export-dynamic-symbol) it is libhwy's own.
    void* resolved = dlsym(RTLD_DEFAULT, "_ZN3hwy8platform15TimerResolutionEv");
    ASSERT_NE(resolved, nullptr);
    EXPECT_EQ(resolved, reinterpret_cast<void*>(&hwy::platform::TimerResolution));
    // libhwy defines it too (this test binary may not need libhwy: then it is loaded here, and
    // its initialiser's call resolves the same way).
    void* hwy = dlopen("libhwy.so.1", RTLD_NOW);
    ASSERT_NE(hwy, nullptr) << dlerror();
    void* own = dlsym(hwy, "_ZN3hwy8platform15TimerResolutionEv");
    dlclose(hwy);
    EXPECT_NE(own, nullptr);
    EXPECT_NE(own, resolved);
}

}  // namespace
}  // namespace vdbsplat
