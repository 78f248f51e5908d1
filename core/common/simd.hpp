#pragma once
// OpenCV's universal intrinsics (v_uint16x8 and friends: SSE on x86, NEON on ARM), the one way the
// optimised kernels vectorise. Include this instead of opencv2/core/hal/intrin.hpp.
//
// Outside OpenCV's own build its headers assume plain SSE2 on x86 and pick the SSSE3/SSE4.1 forms
// (a native unsigned 16-bit minimum, byte alignment, horizontal minimum) only when CV_SSSE3 and
// CV_SSE4_1 are set. The build sets them with -march=x86-64-v2 (ICEWATCH_X86_64_LEVEL in
// CMakeLists.txt); the instruction headers they then need come here, before OpenCV's.
#if defined(__SSE4_1__)
#include <smmintrin.h>
#include <tmmintrin.h>
#endif

#include <opencv2/core/hal/intrin.hpp>
