// recording.json: any content gives a Recording or an Error naming the file (65 or 66).
#include <cstdlib>

#include "core/common/error.hpp"
#include "drivers/v4l2/recording.hpp"
#include "fuzz/scratch_dir.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const auto& dir = icewatch::fuzz::scratchDir();
    static const bool framesWritten = [&dir] {
        // Two small frames, so that a valid index gets as far as the size checks.
        const char frame[16] = {};
        icewatch::fuzz::writeFile(dir / "000001.jpg", frame, sizeof frame);
        icewatch::fuzz::writeFile(dir / "000002.jpg", frame, sizeof frame);
        return true;
    }();
    (void)framesWritten;
    icewatch::fuzz::writeFile(dir / "recording.json", reinterpret_cast<const char*>(data), size);
    try {
        icewatch::v4l2::readRecording(dir);
    } catch (const icewatch::Error& e) {
        if (e.code() != icewatch::kExitDataErr && e.code() != icewatch::kExitNoInput) std::abort();
    }
    return 0;
}
