// The real capture code replaying recordings through the fake uvcvideo device: frames come out
// split into the right eyes with the source's pixels, and every scripted fault is survived with
// nothing corrupt passed on. The fake runs at fast pace and back-off delays are recorded, not
// slept, so no test waits on a clock.
#include "drivers/v4l2/camera_capture.hpp"

#include <gtest/gtest.h>

#include "core/common/error.hpp"
#include "drivers/v4l2/device_seam.hpp"
#include "drivers/v4l2/fake_uvc_device.hpp"
#include "tests/drivers/v4l2/test_recording.hpp"
#include "tests/support/test_paths.hpp"

namespace icewatch::v4l2 {
namespace {

using Kind = FakeFault::Kind;
using std::chrono::milliseconds;

class Replay {
public:
    explicit Replay(FakeUvcOptions options = {}, const std::function<void(config::CameraConfig&)>& tweak = {},
                    bool yuyv = false) {
        const auto dir = test::freshTempDir() / "recording";
        recording_ = yuyv ? test::makeYuyvRecording(dir) : test::makeMjpegRecording(dir);
        sources_ = test::decodeRecording(recording_);
        options.pace = FakeUvcOptions::Pace::kFast;
        fake_ = std::make_unique<FakeUvcDevice>(recording_, options);
        config_.device = "fake:" + dir.string();
        config_.format = formatName(recording_.format);
        config_.width = recording_.width;
        config_.height = recording_.height;
        config_.fps = recording_.fps;
        if (tweak) tweak(config_);
        CaptureOptions captureOptions;
        captureOptions.sleep = [this](milliseconds d) { sleeps_.push_back(d.count()); };
        capture_ = std::make_unique<CameraCapture>(config_, *fake_, fake_->devicePath(), captureOptions);
    }

    // Calls grab() `calls` times; returns the source index of every frame handed out (-1 for a
    // frame that matches no source: a corrupt one) and records every error.
    std::vector<int> grab(int calls) {
        std::vector<int> indices;
        for (int i = 0; i < calls; ++i) {
            CapturedFrame frame;
            const CaptureError e = capture_->grab(frame);
            errors_.push_back(e);
            if (e == CaptureError::kNone) {
                EXPECT_EQ(frame.pair.left.cols, recording_.width / 2);
                EXPECT_EQ(frame.pair.left.rows, recording_.height);
                EXPECT_EQ(frame.pair.right.size(), frame.pair.left.size());
                indices.push_back(test::matchingSource(frame.pair, sources_));
            }
        }
        return indices;
    }

    FakeUvcDevice& fake() { return *fake_; }
    CameraCapture& capture() { return *capture_; }
    const std::vector<CaptureError>& errors() const { return errors_; }
    const std::vector<std::int64_t>& sleeps() const { return sleeps_; }
    const Recording& recording() const { return recording_; }
    std::uint64_t dropped(DropReason r) const { return capture_->stats().dropped[static_cast<std::size_t>(r)]; }

private:
    Recording recording_;
    std::vector<StereoPair> sources_;
    std::unique_ptr<FakeUvcDevice> fake_;
    config::CameraConfig config_;
    std::vector<std::int64_t> sleeps_;
    std::vector<CaptureError> errors_;
    std::unique_ptr<CameraCapture> capture_;
};

FakeUvcOptions withFault(Kind kind, std::size_t atFrame, int count = 1) {
    FakeUvcOptions o;
    o.faults.push_back({kind, atFrame, count});
    return o;
}

std::vector<CaptureError> noErrors(std::size_t n) { return std::vector<CaptureError>(n, CaptureError::kNone); }

TEST(CameraCapture, ReplaysEveryFrameInOrderSplitIntoEyesWithTheSourcePixels) {
    Replay r;
    EXPECT_EQ(r.grab(8), (std::vector<int>{0, 1, 2, 3, 4, 5, 6, 7}));
    EXPECT_EQ(r.errors(), noErrors(8));
    EXPECT_EQ(r.capture().mode().width, 1280);
    EXPECT_EQ(r.capture().mode().height, 480);
    EXPECT_EQ(r.capture().mode().fps, 30);
    EXPECT_FALSE(r.capture().mode().substituted);
    EXPECT_EQ(r.capture().mode().driver, "uvcvideo");
    EXPECT_EQ(r.capture().stats().droppedTotal(), 0u);
    EXPECT_EQ(r.capture().stats().delivered, 8u);
}

TEST(CameraCapture, KeepsStreamingPastTheEndOfTheRecordingLikeACamera) {
    Replay r;
    EXPECT_EQ(r.grab(11), (std::vector<int>{0, 1, 2, 3, 4, 5, 6, 7, 0, 1, 2}));
}

TEST(CameraCapture, ReplaysYuyvFrames) {
    Replay r({}, {}, /*yuyv=*/true);
    EXPECT_EQ(r.grab(4), (std::vector<int>{0, 1, 2, 3}));
    EXPECT_EQ(r.capture().mode().format, PixelFormat::kYuyv);
}

TEST(CameraCapture, HandsOutTheFreshestFrameAndRequeuesTheOlderOnes) {
    // Frames 2, 3 and 4 arrive at once: the consumer fell behind, it gets 4 and 2, 3 go back.
    Replay r(withFault(Kind::kBurst, 2, 3));
    EXPECT_EQ(r.grab(4), (std::vector<int>{0, 1, 4, 5}));
    EXPECT_EQ(r.capture().stats().skipped, 2u);
    EXPECT_EQ(r.capture().stats().droppedTotal(), 0u);
}

struct DropCase {
    Kind kind;
    DropReason reason;
};

class DropsBadFrames : public ::testing::TestWithParam<DropCase> {};

TEST_P(DropsBadFrames, DropsCountsAndCarriesOn) {
    Replay r(withFault(GetParam().kind, 2));
    const std::vector<int> got = r.grab(6);
    // Frame 2 is bad: that wake-up hands out nothing, and nothing corrupt ever comes out.
    EXPECT_EQ(got, (std::vector<int>{0, 1, 3, 4, 5}));
    EXPECT_EQ(r.errors()[2], CaptureError::kNoValidFrame);
    EXPECT_EQ(r.dropped(GetParam().reason), 1u);
    EXPECT_EQ(r.capture().stats().droppedTotal(), 1u);
    EXPECT_TRUE(r.capture().isStreaming());
}

INSTANTIATE_TEST_SUITE_P(Faults, DropsBadFrames,
                         ::testing::Values(DropCase{Kind::kErrorFlag, DropReason::kErrorFlag},
                                           DropCase{Kind::kZeroBytes, DropReason::kShortFrame},
                                           DropCase{Kind::kTruncatedJpeg, DropReason::kNoJpegMarkers},
                                           DropCase{Kind::kUnknownIndex, DropReason::kBadIndex}),
                         [](const auto& param) { return std::string(dropReasonName(param.param.reason)); });

TEST(CameraCapture, SurvivesAnUnplugAndResumesWhenTheCameraReturns) {
    FakeUvcOptions o = withFault(Kind::kUnplug, 3);
    o.replugAfterOpenAttempts = 2;
    Replay r(o);
    const std::vector<int> got = r.grab(7);
    EXPECT_EQ(r.errors(), (std::vector<CaptureError>{CaptureError::kNone, CaptureError::kNone, CaptureError::kNone,
                                                     CaptureError::kDisconnected, CaptureError::kNoDevice,
                                                     CaptureError::kNoDevice, CaptureError::kNone}));
    EXPECT_EQ(got, (std::vector<int>{0, 1, 2, 3}));
    // Back-off doubles while the camera is away and starts over once it is back.
    EXPECT_EQ(r.sleeps(), (std::vector<std::int64_t>{500, 1000, 2000}));
    EXPECT_EQ(r.capture().nextBackoff(), milliseconds(500));
    EXPECT_EQ(r.capture().stats().disconnects, 1u);
    EXPECT_EQ(r.capture().stats().starts, 2u);
    // Everything of the vanished device was released: one open file, one set of mappings.
    EXPECT_EQ(r.fake().openFds(), 1);
    EXPECT_EQ(r.fake().liveMappings(), r.capture().mode().buffers);
    EXPECT_EQ(r.grab(2), (std::vector<int>{4, 5}));
}

TEST(CameraCapture, BackOffIsCappedWhileTheCameraStaysAway) {
    FakeUvcOptions o = withFault(Kind::kUnplug, 1);
    o.replugAfterOpenAttempts = 1000;
    Replay r(o, [](config::CameraConfig& c) { c.reconnectMaxMs = 3000; });
    r.grab(7);
    EXPECT_EQ(r.sleeps(), (std::vector<std::int64_t>{500, 1000, 2000, 3000, 3000}));
    EXPECT_EQ(r.errors().back(), CaptureError::kNoDevice);
    EXPECT_NE(r.capture().lastError().find("No such file"), std::string::npos) << r.capture().lastError();
}

TEST(CameraCapture, RestartsAStalledCamera) {
    Replay r(withFault(Kind::kStall, 2));
    const std::vector<int> got = r.grab(5);
    EXPECT_EQ(r.errors()[2], CaptureError::kStalled);
    EXPECT_EQ(got, (std::vector<int>{0, 1, 2, 3}));
    EXPECT_EQ(r.capture().stats().stalls, 1u);
    EXPECT_EQ(r.sleeps(), (std::vector<std::int64_t>{500}));
}

TEST(CameraCapture, RetriesAnInterruptedWait) {
    Replay r(withFault(Kind::kInterrupt, 1));
    EXPECT_EQ(r.grab(4), (std::vector<int>{0, 1, 2, 3}));
    EXPECT_EQ(r.errors(), noErrors(4));
    EXPECT_EQ(r.capture().stats().interrupts, 1u);
}

TEST(CameraCapture, DetectsAndReportsASilentlySubstitutedMode) {
    FakeUvcOptions o;
    o.substituteMode = true;
    Replay r(o, [](config::CameraConfig& c) {
        c.width = 3840;
        c.height = 1080;
    });
    EXPECT_EQ(r.grab(3), (std::vector<int>{0, 1, 2}));
    EXPECT_TRUE(r.capture().mode().substituted);
    EXPECT_EQ(r.capture().mode().width, 1280);
    EXPECT_EQ(r.capture().mode().height, 480);
}

TEST(CameraCapture, NeverPassesOnFramesOfAnotherSizeThanNegotiated) {
    // The device agrees to 2560x720 but streams the recording's 1280x480 JPEGs.
    Replay r({}, [](config::CameraConfig& c) {
        c.width = 2560;
        c.height = 720;
    });
    EXPECT_TRUE(r.grab(4).empty());
    EXPECT_EQ(r.dropped(DropReason::kSizeMismatch), 4u);
    EXPECT_FALSE(r.capture().mode().substituted);
}

TEST(CameraCapture, AcceptsFewerBuffersThanAsked) {
    FakeUvcOptions o;
    o.maxBuffers = 2;
    Replay r(o, [](config::CameraConfig& c) { c.buffers = 6; });
    EXPECT_EQ(r.grab(4), (std::vector<int>{0, 1, 2, 3}));
    EXPECT_EQ(r.capture().mode().buffers, 2u);
    EXPECT_EQ(r.fake().liveMappings(), 2u);
}

TEST(CameraCapture, SetsControlsByTheirV4l2CtlNames) {
    Replay r({}, [](config::CameraConfig& c) {
        c.controls = {{"exposure_time_absolute", 300}, {"auto_exposure", 1}, {"gain", 12}};
    });
    ASSERT_EQ(r.capture().start(), CaptureError::kNone);
    EXPECT_EQ(r.fake().controlValue("auto_exposure"), 1);
    EXPECT_EQ(r.fake().controlValue("exposure_time_absolute"), 300);
    EXPECT_EQ(r.fake().controlValue("gain"), 12);
    EXPECT_EQ(r.capture().mode().controls.at("exposure_time_absolute"), 300);
}

TEST(CameraCapture, RejectsUnknownAndOutOfRangeControlsNamingThem) {
    Replay unknown({}, [](config::CameraConfig& c) { c.controls = {{"exposure_absolut", 300}}; });
    EXPECT_EQ(unknown.capture().start(), CaptureError::kBadControl);
    EXPECT_NE(unknown.capture().lastError().find("camera.controls.exposure_absolut"), std::string::npos);
    EXPECT_NE(unknown.capture().lastError().find("exposure_time_absolute"), std::string::npos);
    EXPECT_EQ(unknown.fake().openFds(), 0);

    Replay range({}, [](config::CameraConfig& c) { c.controls = {{"gain", 1000}}; });
    EXPECT_EQ(range.capture().start(), CaptureError::kBadControl);
    EXPECT_NE(range.capture().lastError().find("0 to 100"), std::string::npos) << range.capture().lastError();
    EXPECT_EQ(exitCodeFor(CaptureError::kBadControl), kExitConfig);
}

TEST(CameraCapture, RecordsFramesInOrderByteForByte) {
    Replay r;
    for (std::size_t i = 0; i < r.recording().frames.size(); ++i) {
        RawFrame frame;
        ASSERT_EQ(r.capture().nextRaw(frame), CaptureError::kNone);
        EXPECT_EQ(frame.bytes, r.recording().readFrame(i)) << "frame " << i;
        EXPECT_EQ(frame.sequence, i);
    }
}

TEST(CameraCapture, RealDeviceErrorsThroughLibc) {
    config::CameraConfig config;
    LibcSyscalls libc;
    CaptureOptions options;
    options.sleep = [](milliseconds) {};
    CameraCapture missing(config, libc, "/dev/v4l/by-id/usb-no-such-camera-video-index0", options);
    EXPECT_EQ(missing.start(), CaptureError::kNoDevice);
    CameraCapture notVideo(config, libc, "/dev/null", options);
    EXPECT_EQ(notVideo.start(), CaptureError::kNotCaptureDevice);
    EXPECT_NE(notVideo.lastError().find("not a V4L2 device"), std::string::npos);
}

TEST(DeviceSeam, FakePrefixReplaysARecordingAndAnythingElseIsLibc) {
    const auto dir = test::freshTempDir() / "rec";
    test::makeMjpegRecording(dir, 2);
    DeviceSeam fake = makeDeviceSeam("fake:" + dir.string());
    ASSERT_NE(fake.fake, nullptr);
    EXPECT_EQ(fake.path, dir.string());
    DeviceSeam real = makeDeviceSeam("/dev/video0");
    EXPECT_EQ(real.fake, nullptr);
    EXPECT_EQ(real.path, "/dev/video0");
    EXPECT_THROW(makeDeviceSeam("fake:" + (dir / "missing").string()), Error);
}

}  // namespace
}  // namespace icewatch::v4l2
