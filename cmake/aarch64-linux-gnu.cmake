# Cross build for a 64-bit ARM box on a Debian x86-64 machine (tools/dev arm64): Debian's cross
# compiler (g++-aarch64-linux-gnu) against a sysroot of Debian's arm64 packages, unpacked apart from
# the host's (ICEWATCH_ARM64_SYSROOT; tools/dev makes it with mmdebstrap), since some of OpenCV's
# arm64 packages cannot be installed beside the host's own. The tests run under qemu's user-mode
# emulation, so the NEON forms of the universal intrinsics are executed, not only compiled.
set(CMAKE_SYSTEM_NAME Linux)
set(CMAKE_SYSTEM_PROCESSOR aarch64)
set(CMAKE_C_COMPILER aarch64-linux-gnu-gcc)
set(CMAKE_CXX_COMPILER aarch64-linux-gnu-g++)

if(NOT ICEWATCH_ARM64_SYSROOT)
  set(ICEWATCH_ARM64_SYSROOT "$ENV{ICEWATCH_ARM64_SYSROOT}")
endif()
if(NOT ICEWATCH_ARM64_SYSROOT OR NOT EXISTS "${ICEWATCH_ARM64_SYSROOT}/usr/include")
  message(FATAL_ERROR "ICEWATCH_ARM64_SYSROOT must name a directory of unpacked arm64 packages (tools/dev arm64)")
endif()
# CMake's own checks (try_compile) read this file again in projects of their own.
list(APPEND CMAKE_TRY_COMPILE_PLATFORM_VARIABLES ICEWATCH_ARM64_SYSROOT)
set(CMAKE_SYSROOT "${ICEWATCH_ARM64_SYSROOT}")
set(CMAKE_LIBRARY_ARCHITECTURE aarch64-linux-gnu)
# Headers, libraries and packages' CMake files from the sysroot only; programs (pkg-config, qemu)
# from the host.
set(CMAKE_FIND_ROOT_PATH "${ICEWATCH_ARM64_SYSROOT}")
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_PACKAGE ONLY)
set(ENV{PKG_CONFIG_SYSROOT_DIR} "${ICEWATCH_ARM64_SYSROOT}")
set(ENV{PKG_CONFIG_LIBDIR}
    "${ICEWATCH_ARM64_SYSROOT}/usr/lib/aarch64-linux-gnu/pkgconfig:${ICEWATCH_ARM64_SYSROOT}/usr/share/pkgconfig")
# The arm64 dynamic loader and libraries come from the sysroot.
set(CMAKE_CROSSCOMPILING_EMULATOR qemu-aarch64 -L "${ICEWATCH_ARM64_SYSROOT}")
