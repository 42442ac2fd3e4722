# SPDX-License-Identifier: Apache-2.0
# Cross build for the end caps' boards: BeagleBone Black class, ARMv7-A
# (Cortex-A8), hard-float EABI, Debian armhf. Compiler defaults are Debian armhf's
# (-march=armv7-a+fp -mfloat-abi=hard -mthumb), the ABI of the armhf libraries.
# Usage: cmake --preset armhf, or -DCMAKE_TOOLCHAIN_FILE=toolchains/arm-linux-gnueabihf.cmake
set(CMAKE_SYSTEM_NAME Linux)
set(CMAKE_SYSTEM_PROCESSOR armv7l)
set(TENSEGRITY_TRIPLET arm-linux-gnueabihf)
set(TENSEGRITY_QEMU qemu-arm)
include(${CMAKE_CURRENT_LIST_DIR}/debian-multiarch.cmake)
