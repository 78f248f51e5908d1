// Real and simulated time for the service loop.
#include "daemon/clock.hpp"

namespace icewatch::daemon {

void SystemClock::waitUntil(std::unique_lock<std::mutex>& lock, std::condition_variable& cv, TimePoint deadline) {
    const auto remaining = deadline - now();
    if (remaining > TimePoint::duration::zero()) {
        cv.wait_for(lock, remaining);
    }
}

void ManualClock::waitUntil(std::unique_lock<std::mutex>& /*lock*/, std::condition_variable& /*cv*/, TimePoint deadline) {
    TimePoint::rep current = now_.load();
    const TimePoint::rep target = deadline.time_since_epoch().count();
    while (current < target && !now_.compare_exchange_weak(current, target)) {
    }
}

}  // namespace icewatch::daemon
