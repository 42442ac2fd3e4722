# SPDX-License-Identifier: Apache-2.0
# The rooms are the source tree's folders (scripts/layers.json: one folder per
# room), and an include line names the header by its path from the top of the
# tree (#include "core/motor_loop.hpp"), so one plain include directory, the
# source root, serves every target. Which room may include which is kept by
# scripts/check_layers.py (CI and scripts/test.sh run it): the rooms a room's
# files include are the ones layers.json allows, which are the ones its CMake
# target links.

# The room names of scripts/layers.json, so a target cannot name a room that the
# layer check does not know.
function(_tensegrity_read_rooms)
  file(READ ${PROJECT_SOURCE_DIR}/scripts/layers.json layers)
  set_property(DIRECTORY ${PROJECT_SOURCE_DIR} APPEND PROPERTY CMAKE_CONFIGURE_DEPENDS
    ${PROJECT_SOURCE_DIR}/scripts/layers.json)
  string(JSON room_count LENGTH "${layers}" rooms)
  math(EXPR last "${room_count} - 1")
  set(rooms "")
  foreach(i RANGE ${last})
    string(JSON name GET "${layers}" rooms ${i} name)
    list(APPEND rooms ${name})
  endforeach()
  set(TENSEGRITY_ROOMS ${rooms} PARENT_SCOPE)
endfunction()

_tensegrity_read_rooms()

# Every project target: warnings on, and the source root as its include directory
# (PUBLIC, so a target that links it finds the headers it names).
function(tensegrity_target_defaults target)
  cmake_parse_arguments(ARG "" "ROOM" "" ${ARGN})
  if(NOT ARG_ROOM IN_LIST TENSEGRITY_ROOMS)
    message(FATAL_ERROR "tensegrity_target_defaults(${target}): ROOM '${ARG_ROOM}' is not a room of "
      "scripts/layers.json (rooms: ${TENSEGRITY_ROOMS})")
  endif()
  target_link_libraries(${target} PRIVATE tensegrity::warnings)
  get_target_property(type ${target} TYPE)
  if(type STREQUAL "EXECUTABLE")
    target_include_directories(${target} PRIVATE ${PROJECT_SOURCE_DIR})
  else()
    target_include_directories(${target} PUBLIC $<BUILD_INTERFACE:${PROJECT_SOURCE_DIR}>)
  endif()
endfunction()
