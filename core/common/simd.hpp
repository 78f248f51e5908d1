#pragma once
// OpenCV's universal intrinsics (SSE or AVX2 on x86, NEON on ARM), the one way the optimised
// kernels vectorise. Include this instead of opencv2/core/hal/intrin.hpp.
//
// Outside OpenCV's own build its headers assume plain SSE2 on x86 and pick the SSSE3/SSE4.1 forms
// (a native unsigned 16-bit minimum, byte alignment, horizontal minimum) only when CV_SSSE3 and
// CV_SSE4_1 are set, and the 256-bit AVX2 types only when CV_AVX2 is. The build sets them from
// -march (ICEWATCH_X86_64_LEVEL in CMakeLists.txt); the instruction headers they then need come
// here, before OpenCV's.
//
// Kernels whose loop runs along the disparity axis use the widest type (cv::v_uint16 and
// cv::vx_load: 16 lanes with AVX2, 8 with SSE or NEON); the padded disparity axis is a multiple of
// the widest 16-bit vector (kDisparityAlign in stages.hpp).
#if defined(__SSE4_1__)
#include <smmintrin.h>
#include <tmmintrin.h>
#endif
#if defined(__AVX2__)
#include <immintrin.h>
#endif

#include <opencv2/core/hal/intrin.hpp>
