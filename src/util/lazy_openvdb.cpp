// util/lazy_openvdb.cpp — linked into the vdbsplat executable only (CMake option
// VDBSPLAT_LAZY_OPENVDB), never into the core library, the tests or the benchmarks. Owns: the
// function the generated trampolines call the first time each libopenvdb function is used: it
// opens libopenvdb (once per process) and returns the function's address.
//
// Why: an executable that lists libopenvdb.so as NEEDED pays ~45 ms at every start, before
// main(): the dynamic loader resolves the library's ~52k symbolic relocations, mangled names
// of 346 characters on average (docs/performance.md, session 17: `vdbsplat --version` 50 ms, an
// empty program 0.5 ms). So the executable does not link libopenvdb: every libopenvdb function
// it calls is a hidden trampoline of its own (cmake/lazy_openvdb_trampolines.sh generates them
// at build time from nm), which jumps through a slot; each slot starts at a stub that calls
// vdbsplat_lazy_openvdb_resolve below, which stores the real address into the slot. A command
// that never calls into libopenvdb never loads it; one that does pays the same load, later.
//
// Hidden trampolines: libopenvdb, once loaded, binds its own references to its own definitions.
// A broken installation (library or symbol missing) ends the process with one error line:
// there is no caller to return an error to. The slot table, in the generated assembly, is the
// only state besides the library handle.
#include <dlfcn.h>
#include <unistd.h>

#include <cstdio>

extern "C" {
// Defined by the generated assembly, one entry per trampoline.
__attribute__((visibility("hidden"))) extern void* vdbsplat_lazy_openvdb_slots[];  // where trampoline i jumps
__attribute__((visibility("hidden"))) extern const char* const vdbsplat_lazy_openvdb_names[];  // its name

/// Called by the trampolines' common stub with the caller's arguments saved: the address of
/// function @p index, also stored into its slot so that later calls jump straight there.
__attribute__((visibility("hidden"))) void* vdbsplat_lazy_openvdb_resolve(unsigned index) noexcept;
}

namespace {

/// Ends the process: libopenvdb or one of its functions cannot be found.
[[noreturn]] void cannotLoad(const char* why) {
    std::fprintf(stderr, "vdbsplat: error: cannot load %s: %s\n", VDBSPLAT_OPENVDB_SONAME,
                 why != nullptr ? why : "unknown error");
    _exit(1);
}

/// The library's handle, opened by the first caller (a function-local static: thread-safe).
void* library() {
    static void* const handle = [] {
        void* h = dlopen(VDBSPLAT_OPENVDB_SONAME, RTLD_NOW | RTLD_LOCAL);
        if (h == nullptr) cannotLoad(dlerror());
        return h;
    }();
    return handle;
}

}  // namespace

void* vdbsplat_lazy_openvdb_resolve(unsigned index) noexcept {
    void* const handle = library();
    dlerror();  // clear: a null answer is an error only with a message
    void* const address = dlsym(handle, vdbsplat_lazy_openvdb_names[index]);
    if (address == nullptr) cannotLoad(dlerror());
    // Threads may race to resolve the same slot: each stores the same address.
    __atomic_store_n(&vdbsplat_lazy_openvdb_slots[index], address, __ATOMIC_RELEASE);
    return address;
}
