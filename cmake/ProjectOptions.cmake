# SPDX-License-Identifier: Apache-2.0
# Warnings and sanitizer settings shared by every target of the project.

add_library(tensegrity_warnings INTERFACE)
add_library(tensegrity::warnings ALIAS tensegrity_warnings)
target_compile_options(tensegrity_warnings INTERFACE -Wall -Wextra -Wpedantic -Wshadow
  -Wnon-virtual-dtor -Wconversion -Wno-sign-conversion)

# GCC 12 at -O3 reports -Wrestrict inside std::string's own copy for ordinary
# concatenations (GCC bug 105329, fixed in GCC 13): a false positive in libstdc++.
if(CMAKE_CXX_COMPILER_ID STREQUAL "GNU" AND CMAKE_CXX_COMPILER_VERSION VERSION_LESS 13)
  target_compile_options(tensegrity_warnings INTERFACE -Wno-restrict)
endif()

option(TENSEGRITY_WERROR "Treat warnings as errors" ON)
if(TENSEGRITY_WERROR)
  target_compile_options(tensegrity_warnings INTERFACE -Werror)
endif()

option(TENSEGRITY_SANITIZE "Build with AddressSanitizer and UndefinedBehaviorSanitizer" OFF)
if(TENSEGRITY_SANITIZE)
  add_compile_options(-fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=undefined)
  add_link_options(-fsanitize=address,undefined)
endif()
