// render/pending_tables.h — the footprint tables, read while the render sets up.
// Owns: PendingTables, loadOrBuildTables (footprint/tables.h) run on a TBB task from the moment a
// forward render starts; the render bakes its transfer function and builds its voxel stream
// meanwhile, and waits for the tables only where the compositor first needs them. Reading and
// checking the two files and fitting the polynomials take ~0.3 ms, as long as the bake and half
// the stream's set-up: a far render of the Engine at 400² is ~5 ms.
#pragma once
#include <tbb/task_group.h>

#include <exception>
#include <filesystem>

#include "footprint/tables.h"

namespace vdbsplat {

class PendingTables {
public:
    /// @brief Starts loadOrBuildTables(@p dir, @p kernel) on a task (with one thread: when get()
    /// first waits).
    PendingTables(std::filesystem::path dir, const KernelShape& kernel);
    /// Waits for the task if get() never did (a render that failed first), dropping its error.
    ~PendingTables();
    PendingTables(const PendingTables&) = delete;
    PendingTables& operator=(const PendingTables&) = delete;

    /// @brief The kernel the tables are for (known before they are).
    const KernelShape& kernel() const { return kernel_; }
    /// @brief The tables, once loaded; rethrows what loading threw (every call).
    /// @throw Error as loadOrBuildTables.
    const Tables& get();

private:
    const KernelShape& kernel_;
    Tables tables_;
    std::exception_ptr error_;
    tbb::task_group group_;
    bool done_ = false;
};

}  // namespace vdbsplat
