// cli/interrupt.h — what a long command does on Ctrl-C and how it shows its progress.
// Owns: InterruptGuard (SIGINT/SIGTERM set a flag the work polls; one-shot, so a second
// signal takes the default action and stops at once) and ProgressMeter (a bar with ETA on
// stderr when it is a terminal, a line per tenth of the work otherwise, e.g. in a log).
// The signal flag is the one piece of process state: a handler can only reach a global.
#pragma once
#include <signal.h>

#include <chrono>
#include <mutex>
#include <string>

namespace vdbsplat::cli {

/// Installs the handlers for the guard's lifetime and restores the previous ones after.
class InterruptGuard {
public:
    InterruptGuard();
    ~InterruptGuard();
    InterruptGuard(const InterruptGuard&) = delete;
    InterruptGuard& operator=(const InterruptGuard&) = delete;
    bool interrupted() const;
    /// "SIGINT" or "SIGTERM" once interrupted, else "".
    std::string signalName() const;

private:
    struct sigaction oldInt_{}, oldTerm_{};
};

/// "12s", "3m05s", "1h02m".
std::string durationText(double seconds);

/// Reports the fraction of a task done on stderr; safe to call from any thread.
class ProgressMeter {
public:
    /// @param what  the task's name, e.g. "render"
    explicit ProgressMeter(std::string what);
    /// Records @p fraction (0..1) and redraws at most ten times a second (terminal) or
    /// prints a line when a new tenth is reached (otherwise).
    void update(double fraction);
    /// Ends the bar's line on a terminal ("done in …").
    void finish();

private:
    void draw(double fraction, double elapsed, bool final);
    std::string what_;
    bool tty_;
    std::mutex mutex_;
    std::chrono::steady_clock::time_point start_, lastDraw_;
    int lastTenth_ = -1;
    bool drawn_ = false;
};

}  // namespace vdbsplat::cli
