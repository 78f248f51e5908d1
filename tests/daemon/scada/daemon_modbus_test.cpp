// The daemon's own cycle feeding the SCADA interfaces: a rendered ice block played through the
// fake uvcvideo device into the V4L2 capture and the real volume chain, published by the daemon,
// and read back over Modbus TCP with libmodbus's client. The registers must say what latest.json
// says, figure for figure.
#include <modbus.h>

#include <cmath>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "core/synth/scene.hpp"
#include "daemon/baseline_store.hpp"
#include "daemon/daemon.hpp"
#include "daemon/scada/scada_interfaces.hpp"
#include "daemon/v4l2_frame_source.hpp"
#include "daemon/volume_measurement_chain.hpp"
#include "drivers/v4l2/recording.hpp"
#include "tests/daemon/doubles.hpp"
#include "tests/daemon/rig.hpp"
#include "tests/daemon/scada/scada_rig.hpp"

namespace icewatch::daemon::scada::test {
namespace {

using daemon::test::readJsonFile;
using daemon::test::testConfig;
using daemon::test::testEpoch;

TEST(ScadaCycle, ModbusRegistersEqualTheResultDocumentOfARealCycle) {
    const auto dir = icewatch::test::freshTempDir();
    synth::SceneSpec spec;
    spec.kind = synth::SceneKind::Block;
    spec.iceVolumeMm3 = 350000;
    spec.seed = 3;
    spec.frameSize = {1280, 480};
    const synth::SyntheticScene scene = synth::renderScene(spec);
    std::vector<uchar> iced;
    ASSERT_TRUE(cv::imencode(".jpg", scene.after, iced, {cv::IMWRITE_JPEG_QUALITY, 95}));
    v4l2::RecordingWriter camera(dir / "camera", "rendered ice block", v4l2::PixelFormat::kMjpeg, 1280, 480, 30);
    camera.add(iced.data(), iced.size(), 0);
    camera.add(iced.data(), iced.size(), 33333);
    camera.finish();

    config::Config config = testConfig(dir / "state");  // alarm at 200 mm³: this block is an alarm
    config.alarm.latch = true;
    config.camera.device = "fake:" + (dir / "camera").string();
    config.camera.width = spec.frameSize.width;
    config.camera.height = spec.frameSize.height;
    config.daemon.burstFrames = config.daemon.minFrames = 2;
    config.volume.stereoMethod = stereo::Method::Sgbm;
    config.volume.maxDisparity = 64;
    for (const cv::Point2d& corner : scene.roi) config.volume.roiPolygon.insert(config.volume.roiPolygon.end(), {corner.x, corner.y});
    config.scada.modbus.listen = "127.0.0.1:0";
    prepareStateDir(dir / "state");
    std::string error;
    ASSERT_TRUE(saveBaseline(dir / "state", {testEpoch(), "scene", splitSideBySide(scene.before), "test", {}}, error))
        << error;

    v4l2::FakeUvcOptions fastCamera;
    fastCamera.pace = v4l2::FakeUvcOptions::Pace::kFast;
    v4l2::CaptureOptions noSleep;
    noSleep.sleep = [](std::chrono::milliseconds) {};
    ManualClock clock(testEpoch() + std::chrono::minutes(10));
    Daemon service(config, DaemonOptions{{}, "cafe", "scada"}, clock,
                   DaemonParts{std::make_unique<V4l2FrameSource>(config.camera, fastCamera, noSleep),
                               std::make_unique<VolumeMeasurementChain>(scene.calibration, "scene", config.volume),
                               nullptr});
    ScadaInterfaces scada(config.scada, service, nullptr);
    service.setPublicationSink(&scada);
    ModbusClient client(*scada.modbusPort());
    EXPECT_EQ(client.inputRegisters(0, 16).at(kStatusRegister), 3) << "fault until the first result";

    ASSERT_TRUE(service.runOnce());
    const nlohmann::json latest = readJsonFile(dir / "state" / "latest.json");
    ASSERT_EQ(latest["status"], "ok") << latest.dump(2);
    ASSERT_EQ(latest["alarm"], "alarm") << latest.dump(2);
    int failure = 0;
    const auto registers = client.inputRegisters(0, kInputRegisterCount, &failure);
    ASSERT_EQ(registers.size(), 18u) << modbus_strerror(failure);
    EXPECT_EQ(registers[kVersionRegister], 2);
    EXPECT_EQ(registers[kStatusRegister], 0);
    EXPECT_EQ(registers[kAlarmLevelRegister], 2);
    EXPECT_EQ(floatAt(registers, kVolumeRegister), latest["volume_mm3"].get<float>());
    EXPECT_EQ(floatAt(registers, kUncertaintyRegister), latest["uncertainty_mm3"].get<float>());
    EXPECT_EQ(floatAt(registers, kMeanThicknessRegister), latest["mean_thickness_mm"].get<float>());
    EXPECT_EQ(floatAt(registers, kMaxThicknessRegister), latest["max_thickness_mm"].get<float>());
    EXPECT_EQ(floatAt(registers, kMeanThicknessUncertaintyRegister),
              latest["mean_thickness_uncertainty_mm"].get<float>());
    EXPECT_GT(floatAt(registers, kMeanThicknessUncertaintyRegister), 0.0f);
    EXPECT_GT(floatAt(registers, kVolumeRegister), 0.5f * 350000) << "a real measurement of the block";
    EXPECT_EQ(uint32At(registers, kResultTimeRegister), 1767226200u) << latest["time"];
    EXPECT_EQ(uint32At(registers, kResultCountRegister), 1u);
    EXPECT_EQ(client.discreteInputs(0, 5), (std::vector<std::uint8_t>{1, 1, 0, 0, 1}))
        << "alarm, warning, no fault, fresh, latched";

    clock.advance(std::chrono::minutes(30));  // three intervals on: stale
    ASSERT_TRUE(waitFor([&] { return client.discreteInputs(kStale, 1).at(0) == 1; }));
    ASSERT_TRUE(service.runOnce());
    const auto second = client.inputRegisters(0, 16);
    EXPECT_EQ(uint32At(second, kResultCountRegister), 2u);
    EXPECT_EQ(uint32At(second, kResultTimeRegister), 1767226200u + 1800u);
    EXPECT_EQ(client.discreteInputs(kStale, 1).at(0), 0) << "fresh again with the new result";
}

}  // namespace
}  // namespace icewatch::daemon::scada::test
