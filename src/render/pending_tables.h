// render/pending_tables.h — the footprint tables, read while the render sets up.
// Owns: PendingTables, loadOrBuildTables (footprint/tables.h) run on a TBB task from the moment a
// forward render starts; the render bakes its transfer function and builds its voxel stream
// meanwhile, and waits for the tables only where the compositor first needs them. Reading and
// checking the two files and fitting the polynomials take ~0.3 ms, as long as the bake and half
// the stream's set-up: a far render of the Engine at 400² is ~5 ms. A render through kept buffers
// takes the tables an earlier one read (ForwardBuffers::tables) and reads nothing.
#pragma once
#include <tbb/task_group.h>

#include <exception>
#include <filesystem>
#include <memory>

#include "footprint/tables.h"

namespace vdbsplat {

class PendingTables {
public:
    /// @brief Starts loadOrBuildTables(@p dir, @p kernel) on a task (with one thread: when get()
    /// first waits).
    PendingTables(std::filesystem::path dir, const KernelShape& kernel);
    /// @brief Tables already read (for @p kernel): ready, nothing runs.
    PendingTables(std::shared_ptr<const Tables> ready, const KernelShape& kernel);
    /// Waits for the task if get() never did (a render that failed first), dropping its error.
    ~PendingTables();
    PendingTables(const PendingTables&) = delete;
    PendingTables& operator=(const PendingTables&) = delete;

    /// @brief The kernel the tables are for (known before they are).
    const KernelShape& kernel() const { return kernel_; }
    /// @brief The tables, once loaded; rethrows what loading threw (every call).
    /// @throw Error as loadOrBuildTables.
    const Tables& get() { return *shared(); }
    /// @brief The tables as get() gives them, shared (to keep them for the next render).
    /// @throw Error as get().
    const std::shared_ptr<const Tables>& shared();

private:
    const KernelShape& kernel_;
    std::shared_ptr<const Tables> tables_;
    std::exception_ptr error_;
    tbb::task_group group_;
    bool done_ = false;
};

}  // namespace vdbsplat
