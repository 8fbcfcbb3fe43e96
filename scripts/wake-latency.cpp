// scripts/wake-latency.cpp — how long one thread takes to run after another wakes it (a condition
// variable, 200 times, 2 ms apart): the cost a render's parallel passes pay per wake-up on this
// host. Not part of the build; a measurement for docs/performance.md (session 28):
//   g++ -O2 -o /tmp/wake scripts/wake-latency.cpp -lpthread && /tmp/wake
#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <mutex>
#include <thread>
#include <vector>

int main() {
    using Clock = std::chrono::steady_clock;
    constexpr int kWakes = 200;
    std::mutex m;
    std::condition_variable cv;
    bool go = false;
    Clock::time_point sent;
    std::vector<double> latency;
    std::thread waiter([&] {
        for (int i = 0; i < kWakes; ++i) {
            std::unique_lock lock(m);
            cv.wait(lock, [&] { return go; });
            go = false;
            latency.push_back(std::chrono::duration<double, std::micro>(Clock::now() - sent).count());
            cv.notify_one();  // the next wake-up only after this one was taken: none coalesce
        }
    });
    for (int i = 0; i < kWakes; ++i) {
        std::this_thread::sleep_for(std::chrono::microseconds(2000));
        std::unique_lock lock(m);
        go = true;
        sent = Clock::now();
        cv.notify_one();
        cv.wait(lock, [&] { return !go; });
    }
    waiter.join();
    std::sort(latency.begin(), latency.end());
    std::printf("wake-up latency (us): min %.1f  median %.1f  p90 %.1f  max %.1f\n", latency.front(),
                latency[kWakes / 2], latency[kWakes * 9 / 10], latency.back());
    return 0;
}
