// SPDX-License-Identifier: Apache-2.0
#pragma once
// The one way this project replaces a file (policies, checkpoints, curves, end-cap
// stats): a crash at any moment (kill -9, power loss) leaves the old content or the
// new, never a mix. Write a temporary beside the target, rename it over the target;
// durable writes also fsync the temporary before and the directory after.
#include <filesystem>
#include <string>

namespace tensegrity::format {

enum class Durability {
  // fsync file and directory: survives power loss (policies, checkpoints, curves).
  synced,
  // Rename only: readers never see half a file, but the last write may be lost on
  // power loss. For status files rewritten every second (end-cap stats), where an
  // fsync a second would wear an end cap's SD card for nothing.
  atomic_only,
};

// Throws std::system_error naming the path on any failure; the temporary is
// removed then, and the target keeps its old content.
void write_file_atomic(const std::filesystem::path& path, const std::string& content,
                       Durability durability = Durability::synced);
// Makes renames and creations in `dir` durable.
void fsync_directory(const std::filesystem::path& dir);

}  // namespace tensegrity::format
