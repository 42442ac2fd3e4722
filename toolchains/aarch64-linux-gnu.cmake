# SPDX-License-Identifier: Apache-2.0
# Cross build for 64-bit ARM boards (ARMv8-A, Debian arm64).
# Usage: cmake --preset aarch64, or -DCMAKE_TOOLCHAIN_FILE=toolchains/aarch64-linux-gnu.cmake
set(CMAKE_SYSTEM_NAME Linux)
set(CMAKE_SYSTEM_PROCESSOR aarch64)
set(TENSEGRITY_TRIPLET aarch64-linux-gnu)
set(TENSEGRITY_QEMU qemu-aarch64)
include(${CMAKE_CURRENT_LIST_DIR}/debian-multiarch.cmake)
