// SPDX-License-Identifier: Apache-2.0
// Where the guest of the power-cut test is in a policy-store write, told to the
// driver on the serial console. The end cap's own FileStorage is linked with
// -Wl,--wrap=fsync,--wrap=rename (power_cut_marks.cpp): each call it makes is
// announced before it starts and after it returns, and each line has left the
// UART (tcdrain) before the call goes on. A line the driver has therefore happened
// before the cut; the last one says in which step the power went.
#pragma once

#include <cstdint>
#include <string_view>

namespace tensegrity::test::power_cut {

// The deliberately broken writers of the negative control: the real FileStorage
// with some of its fsyncs turned into no-ops.
enum class Break : std::uint8_t { none, no_file_fsync, no_dir_fsync, no_fsync };

bool parse_break(std::string_view text, Break& out);

// Marks go to `path` (the guest's serial port), or to stdout when it cannot be
// opened (the host run that makes the first record).
void open_marks(const char* path);
// One line "PC <tag> <version>", drained to the wire before it returns.
void mark(const char* tag, std::uint64_t version);
// Any other line for the driver, drained the same way.
void say(std::string_view line);

// The version the storage calls that follow belong to, and how to break them.
void set_current(std::uint64_t version, Break how);

}  // namespace tensegrity::test::power_cut
