// SPDX-License-Identifier: Apache-2.0
// Reaches into the end cap's app room (tests/rooms/CMakeLists.txt says who may).
#include "firmware/app/mailbox.hpp"

int rooms_probe_mailbox_size() { return static_cast<int>(sizeof(tensegrity::fw::app::LatestValue<int>)); }
