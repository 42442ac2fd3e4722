# SPDX-License-Identifier: Apache-2.0
# Shared part of the toolchain files for Debian's cross compilers and multiarch
# libraries (dpkg --add-architecture ARCH; apt-get install libfoo-dev:ARCH; see
# scripts/setup-cross.sh). Include it after setting TENSEGRITY_TRIPLET (GNU triplet,
# also Debian's multiarch directory name) and TENSEGRITY_QEMU (qemu-user binary).
#
# Layout on Debian: target libraries in /usr/lib/<triplet>, target-specific headers in
# /usr/include/<triplet>, architecture-independent headers and CMake/pkg-config files
# in /usr/include and /usr/share; the cross compiler's own libc and libstdc++ in
# /usr/<triplet>. Debian's cross GCC already searches all of these.

set(CMAKE_C_COMPILER ${TENSEGRITY_TRIPLET}-gcc-12)
set(CMAKE_CXX_COMPILER ${TENSEGRITY_TRIPLET}-g++-12)
set(CMAKE_LIBRARY_ARCHITECTURE ${TENSEGRITY_TRIPLET})
# -Wno-psabi: silence GCC's notes that the ARM/AArch64 argument-passing ABI of some
# types changed in GCC 7.1/9.1/10.1; everything here is built with GCC 12.
set(CMAKE_CXX_FLAGS_INIT "-Wno-psabi")

# Look for libraries, headers and packages only in the target's places: the cross
# compiler's root and the multiarch root "/" (narrowed to /usr/lib/<triplet> by
# CMAKE_LIBRARY_ARCHITECTURE, so no x86_64 library is ever picked). Programs (code
# generators such as fastddsgen) are the build machine's.
set(CMAKE_FIND_ROOT_PATH /usr/${TENSEGRITY_TRIPLET} /)
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_PACKAGE ONLY)
# find_package(... CONFIG) must not fall back to /usr/lib/x86_64-linux-gnu/cmake
# through the package registry or the host's system prefix.
set(CMAKE_FIND_USE_PACKAGE_REGISTRY OFF)

# pkg-config: only the target's .pc files (else libssl, say, resolves to x86_64's).
set(ENV{PKG_CONFIG_LIBDIR} "/usr/lib/${TENSEGRITY_TRIPLET}/pkgconfig:/usr/share/pkgconfig")
set(ENV{PKG_CONFIG_PATH} "")
unset(ENV{PKG_CONFIG_SYSROOT_DIR})

# Run target programs (ctest, gtest_discover_tests at build time) under qemu-user.
# No -L/QEMU_LD_PREFIX: the multiarch dynamic loader sits at /lib/ld-linux-*.so.*
# and pairs with the libc in /usr/lib/<triplet>; pointing qemu at /usr/<triplet>
# mixes the cross compiler's libc with the multiarch loader.
find_program(TENSEGRITY_QEMU_PATH NAMES ${TENSEGRITY_QEMU} ${TENSEGRITY_QEMU}-static
  NO_CMAKE_FIND_ROOT_PATH)
if(TENSEGRITY_QEMU_PATH)
  set(CMAKE_CROSSCOMPILING_EMULATOR ${TENSEGRITY_QEMU_PATH})
else()
  # Still lets the project configure and build; running tests will fail clearly.
  set(CMAKE_CROSSCOMPILING_EMULATOR ${TENSEGRITY_QEMU})
endif()
