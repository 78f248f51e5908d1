// icewatchd's parts wired as in production: a recording of a rendered ice block played through
// the fake uvcvideo device and the real V4L2 capture, the real volume chain, fake GPIO lines, on
// simulated time; the camera is unplugged in the middle of a burst and comes back.
#include <gtest/gtest.h>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "core/calib/stereo_calibration.hpp"
#include "core/synth/scene.hpp"
#include "daemon/baseline_store.hpp"
#include "daemon/v4l2_frame_source.hpp"
#include "daemon/volume_measurement_chain.hpp"
#include "daemon/wiring.hpp"
#include "drivers/v4l2/recording.hpp"
#include "tests/daemon/rig.hpp"

namespace icewatch::daemon::test {
namespace {

using gpio::LineTransition;

// A rendered ice block at a sixth of the camera's resolution, one sample a pixel: quick to measure.
synth::SyntheticScene smallIceBlock() {
    synth::SceneSpec spec;
    spec.kind = synth::SceneKind::Block;
    spec.iceVolumeMm3 = 417391;
    spec.frameSize = {640, 240};
    spec.supersampling = 1;
    return synth::renderScene(spec);
}

TEST(EndToEnd, RecordingThroughTheFakeCameraWithAnUnplugMidBurst) {
    const auto dir = icewatch::test::freshTempDir();
    synth::SceneSpec spec;
    spec.kind = synth::SceneKind::Block;
    spec.iceVolumeMm3 = 427174;
    spec.seed = 2;
    spec.frameSize = {1280, 480};
    const synth::SyntheticScene scene = synth::renderScene(spec);

    // The iced blade as the camera sends it: MJPEG frames of the after capture.
    std::vector<uchar> jpeg;
    ASSERT_TRUE(cv::imencode(".jpg", scene.after, jpeg, {cv::IMWRITE_JPEG_QUALITY, 95}));
    v4l2::RecordingWriter writer(dir / "recording", "synthetic ice block", v4l2::PixelFormat::kMjpeg, 1280, 480, 30);
    for (int i = 0; i < 4; ++i) writer.add(jpeg.data(), jpeg.size(), i * 33333);
    writer.finish();

    config::Config config = testConfig(dir / "state");
    config.camera.device = "fake:" + (dir / "recording").string();
    config.camera.width = 1280;
    config.camera.height = 480;
    config.daemon.burstFrames = 2;
    config.daemon.minFrames = 2;
    config.daemon.cameraCheckS = 300;
    config.alarm.warningSet = 300000;
    config.alarm.warningClear = 250000;
    config.alarm.alarmSet = 600000;
    config.alarm.alarmClear = 500000;
    config.volume.stereoMethod = stereo::Method::Sgbm;
    config.volume.maxDisparity = 64;
    for (const auto& p : scene.roi) {
        config.volume.roiPolygon.push_back(p.x);
        config.volume.roiPolygon.push_back(p.y);
    }

    // The clean-blade reference, stored as `icewatch baseline capture` stores it.
    prepareStateDir(dir / "state");
    std::string error;
    ASSERT_TRUE(saveBaseline(dir / "state", {testEpoch(), "scene", splitSideBySide(scene.before), "test", {}}, error)) << error;

    // The device's frame 5 is the second frame of cycle 2's burst (00:10; cycle 1 and the camera
    // check at 00:05 used the earlier ones): the cable is pulled there. The device comes back on
    // the third open, which the checks and cycles after it try.
    v4l2::FakeUvcOptions fake;
    fake.pace = v4l2::FakeUvcOptions::Pace::kFast;
    fake.faults = {{v4l2::FakeFault::Kind::kUnplug, 5}};
    fake.replugAfterOpenAttempts = 2;
    v4l2::CaptureOptions capture;
    capture.sleep = [](std::chrono::milliseconds) {};

    ManualClock clock(testEpoch());
    auto gpioLog = std::make_shared<gpio::TransitionLog>();
    DaemonParts parts{std::make_unique<V4l2FrameSource>(config.camera, fake, capture),
                      std::make_unique<VolumeMeasurementChain>(scene.calibration, "scene", config.volume),
                      gpio::openScadaOutputs(config.gpio, gpioLog)};
    auto daemon = std::make_unique<Daemon>(config, DaemonOptions{{}, "cafe", "e2e"}, clock, std::move(parts));
    daemon->runUntil(testEpoch() + std::chrono::minutes(25));

    const auto rows = daemon->history(testEpoch(), 100);
    ASSERT_GE(rows.size(), 3u);
    const nlohmann::json& first = rows.front();
    ASSERT_EQ(first["status"], "ok") << first.dump(2);
    const double volume = first["volume_mm3"].get<double>();
    const double uncertainty = first["uncertainty_mm3"].get<double>();
    // One rendered frame replayed (no averaging gain) at a third of the camera's resolution: the
    // uncertainty must cover the error.
    EXPECT_LT(std::abs(volume - scene.iceVolumeMm3), uncertainty)
        << "measured " << volume << " ± " << uncertainty << ", truth " << scene.iceVolumeMm3;
    EXPECT_LT(std::abs(volume - scene.iceVolumeMm3), 0.25 * scene.iceVolumeMm3);
    EXPECT_EQ(first["alarm"], "warning");
    EXPECT_EQ(first["camera"], "ok");

    EXPECT_EQ(rows[1]["status"], "fault") << rows[1].dump(2);
    EXPECT_EQ(rows[1]["camera"], "offline");
    EXPECT_NE(rows[1]["reason"].get<std::string>().find("camera lost at frame 2 of the burst"), std::string::npos)
        << rows[1]["reason"];
    EXPECT_EQ(rows[1]["alarm"], "fault");

    EXPECT_EQ(rows.back()["status"], "ok") << rows.back().dump(2);
    EXPECT_EQ(rows.back()["camera"], "ok");
    EXPECT_EQ(rows.back()["alarm"], "warning");
    const nlohmann::json latest = readJsonFile(dir / "state" / "latest.json");
    EXPECT_EQ(latest["time"], rows.back()["time"]);
    EXPECT_TRUE(std::filesystem::exists(dir / "state" / "images" / "thickness.png"));

    daemon.reset();
    EXPECT_EQ(gpioLog->transitions(), (std::vector<LineTransition>{{"alarm", true},
                                                                    {"healthy", true},  // warning: healthy
                                                                    {"healthy", false},
                                                                    {"alarm", false},  // unplugged: fault
                                                                    {"alarm", true},
                                                                    {"healthy", true},  // back
                                                                    {"healthy", false},
                                                                    {"alarm", false}}));  // shutdown
}

TEST(EndToEnd, ARefusedMeasurementKeepsItsPicturesWithTheReason) {
    const synth::SyntheticScene scene = smallIceBlock();
    volume::Parameters parameters;
    parameters.stereoMethod = stereo::Method::Sgbm;
    for (const auto& p : scene.roi) {
        parameters.roiPolygon.push_back(p.x);
        parameters.roiPolygon.push_back(p.y);
    }
    VolumeMeasurementChain chain(scene.calibration, "scene", parameters, {5.0});
    ASSERT_EQ(chain.setBaseline(splitSideBySide(scene.before), {}).status, ChainResult::Status::Ok);
    // Night: the gate refuses what the matcher saw.
    const cv::Mat night = scene.after * 0.05;
    const ChainResult refused = chain.estimate(splitSideBySide(night), {});
    ASSERT_EQ(refused.status, ChainResult::Status::Refused) << refused.reason;
    for (const cv::Mat* picture : {&refused.pictures.left, &refused.pictures.disparity, &refused.pictures.thickness}) {
        ASSERT_FALSE(picture->empty());
        cv::Mat white;
        cv::inRange((*picture)(cv::Rect(0, 0, picture->cols, 30)), cv::Scalar::all(200), cv::Scalar::all(255), white);
        EXPECT_GT(cv::countNonZero(white), 20) << "the reason written across the top";
    }
    const ChainResult measured = chain.estimate(splitSideBySide(scene.after), {});
    ASSERT_EQ(measured.status, ChainResult::Status::Ok) << measured.reason;
    EXPECT_GT(measured.pictures.thickness.cols, 320) << "the eye and its colour bar";
}

// The daemon's chain matches with the configuration's "stereo" section, as icewatch volume does:
// a matcher setting changed there changes what the daemon measures.
TEST(EndToEnd, TheDaemonsChainMatchesAsTheConfigurationSays) {
    const auto dir = icewatch::test::freshTempDir();
    const synth::SyntheticScene scene = smallIceBlock();
    config::Config config = testConfig(dir / "state");
    config.calibration.file = (dir / "calibration.yaml").string();
    calib::saveCalibration(config.calibration.file, scene.calibration);
    config.volume.stereoMethod = stereo::Method::Sgbm;
    for (const auto& p : scene.roi) {
        config.volume.roiPolygon.push_back(p.x);
        config.volume.roiPolygon.push_back(p.y);
    }
    auto measured = [&](const config::Config& c) {
        const std::unique_ptr<MeasurementChain> chain = makeMeasurementChain(c);
        EXPECT_EQ(chain->setBaseline(splitSideBySide(scene.before), {}).status, ChainResult::Status::Ok);
        const ChainResult r = chain->estimate(splitSideBySide(scene.after), {});
        EXPECT_EQ(r.status, ChainResult::Status::Ok) << r.reason;
        return r.volumeMm3;
    };
    const double asShipped = measured(config);
    config.stereo.sgbmBlockSize = 11;
    EXPECT_NE(measured(config), asShipped) << "the matcher's block size reached the daemon's chain";
}

}  // namespace
}  // namespace icewatch::daemon::test
