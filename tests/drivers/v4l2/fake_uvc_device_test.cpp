// The fake camera answers like uvcvideo at the ioctl level, through the same V4l2Device the
// capture uses: if it did not, the capture tests would prove nothing about a real camera.
#include "drivers/v4l2/fake_uvc_device.hpp"

#include <cerrno>
#include <cstring>

#include <gtest/gtest.h>
#include <sys/mman.h>

#include "drivers/v4l2/v4l2_device.hpp"
#include "tests/drivers/v4l2/test_recording.hpp"
#include "tests/support/test_paths.hpp"

namespace icewatch::v4l2 {
namespace {

class FakeDevice : public ::testing::Test {
protected:
    void SetUp() override {
        recording_ = test::makeMjpegRecording(test::freshTempDir() / "rec", 3, 64, 48);
        options_.pace = FakeUvcOptions::Pace::kFast;
    }
    Recording recording_;
    FakeUvcOptions options_;
};

TEST_F(FakeDevice, AnswersQueryCapAndListsTheHbvcamModes) {
    FakeUvcDevice fake(recording_, options_);
    V4l2Device dev(fake);
    EXPECT_EQ(dev.open("/dev/video0"), -ENOENT);
    ASSERT_EQ(dev.open(fake.devicePath()), 0);
    Capability cap;
    ASSERT_EQ(dev.queryCapability(cap), 0);
    EXPECT_EQ(cap.driverName(), "uvcvideo");
    EXPECT_TRUE(cap.isVideoCapture());
    EXPECT_TRUE(cap.hasStreaming());
    std::vector<FormatDescription> formats;
    ASSERT_EQ(dev.enumFormats(formats), 0);
    ASSERT_EQ(formats.size(), 2u);
    EXPECT_EQ(fourccText(formats[0].fourcc), "MJPG");
    EXPECT_EQ(fourccText(formats[1].fourcc), "YUYV");
    std::vector<FrameSize> sizes;
    ASSERT_EQ(dev.enumFrameSizes(V4L2_PIX_FMT_MJPEG, sizes), 0);
    ASSERT_EQ(sizes.size(), 4u);
    EXPECT_EQ(sizes[3].width, 3840);
    EXPECT_EQ(sizes[3].height, 1520);
    std::vector<FrameInterval> intervals;
    ASSERT_EQ(dev.enumFrameIntervals(V4L2_PIX_FMT_MJPEG, sizes[3], intervals), 0);
    EXPECT_EQ(intervals.front().denominator, 10u);
    ASSERT_EQ(dev.enumFrameIntervals(V4L2_PIX_FMT_YUYV, sizes[1], intervals), 0);
    EXPECT_EQ(intervals.front().denominator, 30u);
}

TEST_F(FakeDevice, SnapsFormatAndFrameRateToTheNearestMode) {
    FakeUvcDevice fake(recording_, options_);
    V4l2Device dev(fake);
    ASSERT_EQ(dev.open(fake.devicePath()), 0);
    v4l2_pix_format pix{};
    pix.width = 2500;
    pix.height = 700;
    pix.pixelformat = V4L2_PIX_FMT_YUYV;
    ASSERT_EQ(dev.setFormat(pix), 0);
    EXPECT_EQ(pix.width, 2560u);
    EXPECT_EQ(pix.height, 720u);
    EXPECT_EQ(pix.pixelformat, V4L2_PIX_FMT_YUYV);
    EXPECT_EQ(pix.bytesperline, 2560u * 2);
    FrameInterval interval;
    ASSERT_EQ(dev.setFrameRate(24, interval), 0);
    EXPECT_EQ(interval.denominator, 25u);
    pix = {};
    pix.width = 4000;
    pix.height = 1600;
    pix.pixelformat = V4L2_PIX_FMT_H264;  // unknown: uvcvideo falls back to the first format
    ASSERT_EQ(dev.setFormat(pix), 0);
    EXPECT_EQ(pix.pixelformat, V4L2_PIX_FMT_MJPEG);
    EXPECT_EQ(pix.width, 3840u);
    EXPECT_EQ(pix.height, 1520u);
}

TEST_F(FakeDevice, StreamsIntoRealMappedMemoryWithVb2Semantics) {
    FakeUvcDevice fake(recording_, options_);
    V4l2Device dev(fake);
    ASSERT_EQ(dev.open(fake.devicePath()), 0);
    v4l2_pix_format pix{};
    pix.width = 128;
    pix.height = 48;
    pix.pixelformat = V4L2_PIX_FMT_MJPEG;
    ASSERT_EQ(dev.setFormat(pix), 0);  // snapped to 1280x480: the buffers are large enough anyway
    unsigned count = 3;
    ASSERT_EQ(dev.requestBuffers(count), 0);
    ASSERT_EQ(count, 3u);
    std::vector<std::pair<void*, std::size_t>> maps;
    for (unsigned i = 0; i < count; ++i) {
        v4l2_buffer b;
        ASSERT_EQ(dev.queryBuffer(i, b), 0);
        int error = 0;
        void* address = dev.map(b.length, b.m.offset, error);
        ASSERT_NE(address, nullptr) << std::strerror(error);
        maps.emplace_back(address, b.length);
        ASSERT_EQ(dev.queueBuffer(i), 0);
    }
    EXPECT_EQ(dev.queueBuffer(0), -EINVAL);  // already queued
    EXPECT_EQ(dev.setFormat(pix), -EBUSY);   // buffers exist
    v4l2_buffer b;
    EXPECT_EQ(dev.dequeueBuffer(b), -EINVAL);  // not streaming
    ASSERT_EQ(dev.streamOn(), 0);
    EXPECT_EQ(dev.dequeueBuffer(b), -EAGAIN);  // nothing due yet
    short revents = 0;
    ASSERT_EQ(dev.waitReadable(1000, revents), 1);
    EXPECT_TRUE(revents & POLLIN);
    ASSERT_EQ(dev.dequeueBuffer(b), 0);
    const auto frame = recording_.readFrame(0);
    ASSERT_EQ(b.bytesused, frame.size());
    EXPECT_EQ(std::memcmp(maps[b.index].first, frame.data(), frame.size()), 0);
    EXPECT_EQ(b.sequence, 0u);
    ASSERT_EQ(dev.streamOff(), 0);
    unsigned none = 0;
    EXPECT_EQ(dev.requestBuffers(none), -EBUSY);  // still mapped
    for (auto [address, length] : maps) EXPECT_EQ(dev.unmap(address, length), 0);
    EXPECT_EQ(dev.requestBuffers(none), 0);
    EXPECT_EQ(fake.liveMappings(), 0u);
}

TEST_F(FakeDevice, AnUnpluggedDeviceAnswersEnodevAndPollhupThenComesBack) {
    options_.faults.push_back({FakeFault::Kind::kUnplug, 0, 1});
    options_.replugAfterOpenAttempts = 1;
    FakeUvcDevice fake(recording_, options_);
    V4l2Device dev(fake);
    ASSERT_EQ(dev.open(fake.devicePath()), 0);
    unsigned count = 2;
    ASSERT_EQ(dev.requestBuffers(count), 0);
    ASSERT_EQ(dev.queueBuffer(0), 0);
    ASSERT_EQ(dev.streamOn(), 0);
    short revents = 0;
    ASSERT_EQ(dev.waitReadable(1000, revents), 1);
    EXPECT_EQ(revents & (POLLERR | POLLHUP), POLLERR | POLLHUP);
    Capability cap;
    EXPECT_EQ(dev.queryCapability(cap), -ENODEV);
    dev.close();
    EXPECT_EQ(dev.open(fake.devicePath()), -ENOENT);
    EXPECT_EQ(dev.open(fake.devicePath()), 0);
    EXPECT_EQ(dev.queryCapability(cap), 0);
}

TEST_F(FakeDevice, ControlsBehaveLikeUvc) {
    FakeUvcDevice fake(recording_, options_);
    V4l2Device dev(fake);
    ASSERT_EQ(dev.open(fake.devicePath()), 0);
    std::vector<ControlInfo> controls;
    ASSERT_EQ(dev.queryControls(controls), 0);
    auto find = [&](const std::string& name) {
        for (const auto& c : controls) if (c.name == name) return c;
        ADD_FAILURE() << name;
        return ControlInfo{};
    };
    const ControlInfo exposure = find("exposure_time_absolute");
    EXPECT_EQ(exposure.label, "Exposure Time, Absolute");
    EXPECT_TRUE(exposure.flags & V4L2_CTRL_FLAG_INACTIVE);  // auto exposure is on
    const ControlInfo autoExposure = find("auto_exposure");
    ASSERT_EQ(autoExposure.menu.size(), 2u);
    EXPECT_EQ(autoExposure.menu[0].second, "Manual Mode");
    EXPECT_EQ(dev.setControl(V4L2_CID_EXPOSURE_AUTO, 2), -EINVAL);  // not a menu item this camera has
    EXPECT_EQ(dev.setControl(V4L2_CID_GAIN, 500), 0);                // integers are clamped
    std::int32_t gain = 0;
    ASSERT_EQ(dev.getControl(V4L2_CID_GAIN, gain), 0);
    EXPECT_EQ(gain, 100);
}

}  // namespace
}  // namespace icewatch::v4l2
