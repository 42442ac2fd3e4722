# SPDX-License-Identifier: Apache-2.0
# One include root per room, so that the build itself refuses a header of a room
# the target does not link. scripts/layers.json says which files make a room; at
# configure time every header of the tree is linked (a symbolic link, so an edit
# is seen at once) into <build>/rooms/<room>/ under its own path, and a room's
# target exports that folder and nothing else. An include line still names the
# room it reaches into (#include "firmware/core/motor_loop.hpp"), but it resolves
# only through a target that carries that room's root: one the includer links.
# Rooms that may include anything (tests, fuzz, bench: "may_include": ["*"]) see
# the whole tree, privately. scripts/check_layers.py keeps what the build cannot
# see: that a room links only what layers.json allows, and the system headers.

set(TENSEGRITY_ROOMS_DIR ${PROJECT_BINARY_DIR}/rooms)

function(_tensegrity_link_room_headers)
  file(READ ${PROJECT_SOURCE_DIR}/scripts/layers.json layers)
  set_property(DIRECTORY ${PROJECT_SOURCE_DIR} APPEND PROPERTY CMAKE_CONFIGURE_DEPENDS
    ${PROJECT_SOURCE_DIR}/scripts/layers.json)
  string(JSON room_count LENGTH "${layers}" rooms)
  math(EXPR last "${room_count} - 1")
  set(prefixes "")
  set(owners "")
  set(open_rooms "")
  set(top_dirs "")
  foreach(i RANGE ${last})
    string(JSON name GET "${layers}" rooms ${i} name)
    string(JSON first_include ERROR_VARIABLE none GET "${layers}" rooms ${i} may_include 0)
    if(first_include STREQUAL "*")
      list(APPEND open_rooms ${name})
      continue()
    endif()
    string(JSON file_count LENGTH "${layers}" rooms ${i} files)
    math(EXPR last_file "${file_count} - 1")
    foreach(j RANGE ${last_file})
      string(JSON prefix GET "${layers}" rooms ${i} files ${j})
      list(APPEND prefixes ${prefix})
      list(APPEND owners ${name})
      string(REGEX REPLACE "/.*" "" top ${prefix})
      list(APPEND top_dirs ${top})
    endforeach()
  endforeach()
  list(REMOVE_DUPLICATES top_dirs)
  set(globs "")
  foreach(top IN LISTS top_dirs)
    list(APPEND globs ${PROJECT_SOURCE_DIR}/${top}/*.hpp ${PROJECT_SOURCE_DIR}/${top}/*.h)
  endforeach()
  file(GLOB_RECURSE headers CONFIGURE_DEPENDS RELATIVE ${PROJECT_SOURCE_DIR} ${globs})

  # A header moved or deleted must not stay reachable through an old link.
  file(REMOVE_RECURSE ${TENSEGRITY_ROOMS_DIR})
  list(LENGTH prefixes prefix_count)
  math(EXPR last_prefix "${prefix_count} - 1")
  foreach(header IN LISTS headers)
    # The longest matching prefix owns the file, as in scripts/check_layers.py.
    set(owner "")
    set(owner_length 0)
    foreach(k RANGE ${last_prefix})
      list(GET prefixes ${k} prefix)
      string(LENGTH "${prefix}" length)
      string(SUBSTRING "${header}" 0 ${length} head)
      if(head STREQUAL prefix AND length GREATER owner_length)
        list(GET owners ${k} owner)
        set(owner_length ${length})
      endif()
    endforeach()
    if(owner)
      get_filename_component(folder ${TENSEGRITY_ROOMS_DIR}/${owner}/${header} DIRECTORY)
      file(MAKE_DIRECTORY ${folder})
      file(CREATE_LINK ${PROJECT_SOURCE_DIR}/${header} ${TENSEGRITY_ROOMS_DIR}/${owner}/${header} SYMBOLIC)
    endif()
  endforeach()
  set(TENSEGRITY_OPEN_ROOMS ${open_rooms} PARENT_SCOPE)
  list(REMOVE_DUPLICATES owners)
  set(TENSEGRITY_ROOMS ${owners} PARENT_SCOPE)
endfunction()

_tensegrity_link_room_headers()

# Every project target: warnings on, and the include root of the room it is.
function(tensegrity_target_defaults target)
  cmake_parse_arguments(ARG "" "ROOM" "" ${ARGN})
  target_link_libraries(${target} PRIVATE tensegrity::warnings)
  if(ARG_ROOM IN_LIST TENSEGRITY_OPEN_ROOMS)
    target_include_directories(${target} PRIVATE ${PROJECT_SOURCE_DIR})
  elseif(ARG_ROOM IN_LIST TENSEGRITY_ROOMS)
    target_include_directories(${target} PUBLIC $<BUILD_INTERFACE:${TENSEGRITY_ROOMS_DIR}/${ARG_ROOM}>)
  else()
    message(FATAL_ERROR "tensegrity_target_defaults(${target}): ROOM '${ARG_ROOM}' is not a room of "
      "scripts/layers.json (rooms: ${TENSEGRITY_ROOMS}; open: ${TENSEGRITY_OPEN_ROOMS})")
  endif()
endfunction()
