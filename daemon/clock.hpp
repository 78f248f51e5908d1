#pragma once

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <mutex>

namespace icewatch::daemon {

using TimePoint = std::chrono::system_clock::time_point;

// The daemon's only source of time, injected so that tests run a day of 10-minute cycles in
// seconds. now() is called from any thread; waitUntil only from the service loop.
class Clock {
public:
    virtual ~Clock() = default;
    virtual TimePoint now() const = 0;
    // Waits, with lock held on entry and exit, until deadline or until cv is notified (spurious
    // returns are allowed: the caller re-checks).
    virtual void waitUntil(std::unique_lock<std::mutex>& lock, std::condition_variable& cv, TimePoint deadline) = 0;
};

// Wall-clock time; waits are measured on the steady clock so a clock step does not stall the loop.
class SystemClock : public Clock {
public:
    TimePoint now() const override { return std::chrono::system_clock::now(); }
    void waitUntil(std::unique_lock<std::mutex>& lock, std::condition_variable& cv, TimePoint deadline) override;
};

// Simulated time: waiting jumps straight to the deadline.
class ManualClock : public Clock {
public:
    explicit ManualClock(TimePoint start) : now_(start.time_since_epoch().count()) {}
    TimePoint now() const override { return TimePoint(TimePoint::duration(now_.load())); }
    void waitUntil(std::unique_lock<std::mutex>& lock, std::condition_variable& cv, TimePoint deadline) override;
    void advance(TimePoint::duration by) { now_ += by.count(); }

private:
    std::atomic<TimePoint::rep> now_;
};

}  // namespace icewatch::daemon
