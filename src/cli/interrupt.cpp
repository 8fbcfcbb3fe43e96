// cli/interrupt.cpp — see interrupt.h.
#include "cli/interrupt.h"

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>

namespace vdbsplat::cli {

namespace {

std::atomic<int> gSignal{0};

extern "C" void onSignal(int sig) { gSignal.store(sig); }

}  // namespace

InterruptGuard::InterruptGuard() {
    gSignal.store(0);
    struct sigaction sa{};
    sa.sa_handler = onSignal;
    sigemptyset(&sa.sa_mask);
    sa.sa_flags = SA_RESETHAND;
    // A signal ignored when we start (SIGINT of a background job in a script) stays ignored.
    sigaction(SIGINT, nullptr, &oldInt_);
    sigaction(SIGTERM, nullptr, &oldTerm_);
    if (oldInt_.sa_handler != SIG_IGN) sigaction(SIGINT, &sa, nullptr);
    if (oldTerm_.sa_handler != SIG_IGN) sigaction(SIGTERM, &sa, nullptr);
}

InterruptGuard::~InterruptGuard() {
    sigaction(SIGINT, &oldInt_, nullptr);
    sigaction(SIGTERM, &oldTerm_, nullptr);
}

bool InterruptGuard::interrupted() const { return gSignal.load() != 0; }

std::string InterruptGuard::signalName() const {
    switch (gSignal.load()) {
        case 0: return "";
        case SIGINT: return "SIGINT";
        case SIGTERM: return "SIGTERM";
        default: return "signal " + std::to_string(gSignal.load());
    }
}

std::string durationText(double s) {
    char buf[32];
    if (!std::isfinite(s) || s < 0) return "--";
    if (s < 60) std::snprintf(buf, sizeof buf, "%.0fs", s);
    else if (s < 3600) std::snprintf(buf, sizeof buf, "%dm%02ds", int(s) / 60, int(s) % 60);
    else std::snprintf(buf, sizeof buf, "%dh%02dm", int(s) / 3600, (int(s) / 60) % 60);
    return buf;
}

ProgressMeter::ProgressMeter(std::string what)
    : what_(std::move(what)), tty_(::isatty(2) == 1), start_(std::chrono::steady_clock::now()), lastDraw_(start_) {}

void ProgressMeter::update(double fraction) {
    fraction = std::isfinite(fraction) ? std::clamp(fraction, 0.0, 1.0) : 0.0;
    std::unique_lock lock(mutex_, std::try_to_lock);
    if (!lock.owns_lock()) return;  // another thread is drawing: skip this update
    const auto now = std::chrono::steady_clock::now();
    const double elapsed = std::chrono::duration<double>(now - start_).count();
    if (tty_) {
        if (drawn_ && now - lastDraw_ < std::chrono::milliseconds(100)) return;
        lastDraw_ = now;
        draw(fraction, elapsed, false);
    } else {
        const int tenth = int(std::floor(fraction * 10.0));
        if (tenth <= lastTenth_ || tenth >= 10) return;  // the last line is finish()'s
        lastTenth_ = tenth;
        if (tenth > 0) draw(fraction, elapsed, false);
    }
}

void ProgressMeter::finish() {
    std::lock_guard lock(mutex_);
    draw(1.0, std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count(), true);
}

void ProgressMeter::draw(double fraction, double elapsed, bool final) {
    const std::string eta = final ? "done in " + durationText(elapsed)
                            : fraction > 0.01 ? "ETA " + durationText(elapsed / fraction * (1.0 - fraction))
                                              : "ETA --";
    if (tty_) {
        constexpr int kWidth = 30;
        std::string bar(size_t(std::lround(fraction * kWidth)), '#');
        bar.resize(kWidth, ' ');
        std::fprintf(stderr, "\r%s [%s] %3d%%  %s   %s", what_.c_str(), bar.c_str(), int(fraction * 100.0),
                     eta.c_str(), final ? "\n" : "");
    } else {
        std::fprintf(stderr, "%s: %3d%%  %s\n", what_.c_str(), int(fraction * 100.0), eta.c_str());
    }
    std::fflush(stderr);
    drawn_ = true;
}

}  // namespace vdbsplat::cli
