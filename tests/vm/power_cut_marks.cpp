// SPDX-License-Identifier: Apache-2.0
#include "tests/vm/power_cut_marks.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <termios.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <string>

// The names ld's --wrap gives the libc functions and their replacements.
extern "C" {
int __real_fsync(int fd);
int __real_rename(const char* from, const char* to);
int __wrap_fsync(int fd);
int __wrap_rename(const char* from, const char* to);
}

namespace tensegrity::test::power_cut {
namespace {

int g_marks_fd = STDOUT_FILENO;
std::uint64_t g_version = 0;
Break g_break = Break::none;

void write_line(const std::string& line) {
  const char* p = line.data();
  std::size_t left = line.size();
  while (left > 0) {
    const ssize_t n = ::write(g_marks_fd, p, left);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return;  // a mark lost is a phase unknown, not a wrong record
    p += n;
    left -= static_cast<std::size_t>(n);
  }
  // Not on a tty (the host run): nothing to drain.
  if (::isatty(g_marks_fd) == 1) ::tcdrain(g_marks_fd);
}

bool is_directory(int fd) {
  struct stat st {};
  return ::fstat(fd, &st) == 0 && S_ISDIR(st.st_mode);
}

}  // namespace

bool parse_break(std::string_view text, Break& out) {
  struct Name {
    std::string_view text;
    Break how;
  };
  static constexpr Name kNames[] = {{"none", Break::none},
                                    {"no-file-fsync", Break::no_file_fsync},
                                    {"no-dir-fsync", Break::no_dir_fsync},
                                    {"no-fsync", Break::no_fsync}};
  for (const Name& n : kNames) {
    if (n.text == text) {
      out = n.how;
      return true;
    }
  }
  return false;
}

void open_marks(const char* path) {
  const int fd = ::open(path, O_WRONLY | O_NOCTTY | O_CLOEXEC);
  if (fd >= 0) g_marks_fd = fd;
}

void mark(const char* tag, std::uint64_t version) {
  write_line("PC " + std::string(tag) + " " + std::to_string(version) + "\n");
}

void say(std::string_view line) { write_line("PC " + std::string(line) + "\n"); }

void set_current(std::uint64_t version, Break how) {
  g_version = version;
  g_break = how;
}

}  // namespace tensegrity::test::power_cut

using tensegrity::test::power_cut::Break;
using tensegrity::test::power_cut::g_break;
using tensegrity::test::power_cut::g_version;
using tensegrity::test::power_cut::is_directory;
using tensegrity::test::power_cut::mark;

// FileStorage fsyncs the temporary (data) and then the directory (the rename).
extern "C" int __wrap_fsync(int fd) {
  const bool dir = is_directory(fd);
  const bool skip =
      g_break == Break::no_fsync || (dir ? g_break == Break::no_dir_fsync : g_break == Break::no_file_fsync);
  mark(dir ? "DIRSYNC" : "FSYNC", g_version);
  const int rc = skip ? 0 : __real_fsync(fd);
  const int saved = errno;
  mark(dir ? "DIRSYNCED" : "SYNCED", g_version);
  errno = saved;
  return rc;
}

extern "C" int __wrap_rename(const char* from, const char* to) {
  mark("RENAME", g_version);
  const int rc = __real_rename(from, to);
  const int saved = errno;
  mark("RENAMED", g_version);
  errno = saved;
  return rc;
}
