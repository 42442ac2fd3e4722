// SPDX-License-Identifier: Apache-2.0
#pragma once
// Replaces a file so that a crash at any moment (kill -9, power loss) leaves either
// the old content or the new, never a mix: write a temporary beside it, fsync it,
// rename it over the target, fsync the directory.
#include <filesystem>
#include <string>

namespace tensegrity::sim::evolve {

// Throws std::system_error naming the path on any failure.
void write_file_atomic(const std::filesystem::path& path, const std::string& content);
// Makes renames and creations in `dir` durable.
void fsync_directory(const std::filesystem::path& dir);

}  // namespace tensegrity::sim::evolve
