// SPDX-License-Identifier: Apache-2.0
#pragma once
// The messages rank 0 and the evaluating ranks exchange, as bytes. No MPI here, so
// the encoding is tested without mpirun. Integers and doubles are written
// little-endian byte by byte (a double as its IEEE-754 bits), so a score crosses
// machines bit for bit whatever their byte order.
//
//   rank 0 -> rank r: setup (what to evaluate), job (one team), stop
//   rank r -> rank 0: hello (answer to a setup), result (one team's score)
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "sim/evolve/evaluator.hpp"

namespace tensegrity::sim::evolve::wire {

// Bumped whenever a message changes; ranks with another version are refused.
inline constexpr std::uint32_t kProtocol = 1;

// Also the MPI tags.
enum class Tag : int { setup = 1, hello = 2, job = 3, result = 4, stop = 5 };
const char* to_string(Tag tag);

class WireError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

using Bytes = std::vector<unsigned char>;

// What to evaluate: `kind` names the evaluation (e.g. physics episodes) and says how
// to read `payload`; see episode_setup.hpp.
struct Setup {
  std::uint32_t protocol = kProtocol;
  std::string kind;
  std::string payload;
};

struct Hello {
  std::uint32_t protocol = kProtocol;
  std::int32_t threads = 0;  // teams the rank evaluates at once
  std::string host;
  std::string build;  // compiler, C library and CPU family the rank runs
  std::string error;  // the setup failed on the rank; empty otherwise
};

struct Job {
  std::uint64_t batch = 0;  // the evaluate() call, counted from 1
  std::uint64_t index = 0;  // the team's index in it
  Team team;
};

struct Result {
  std::uint64_t batch = 0;
  std::uint64_t index = 0;
  TeamResult result;
  std::string error;  // the evaluation threw this; empty otherwise
};

Bytes encode(const Setup& m);
Bytes encode(const Hello& m);
Bytes encode(const Job& m);
Bytes encode(const Result& m);

// Throw WireError on truncated, oversized or trailing bytes.
Setup decode_setup(const Bytes& bytes);
Hello decode_hello(const Bytes& bytes);
Job decode_job(const Bytes& bytes);
Result decode_result(const Bytes& bytes);

// Field by field, for payloads built on the same encoding (episode_setup).
class Writer {
 public:
  void u8(std::uint8_t v) { bytes_.push_back(v); }
  void u32(std::uint32_t v);
  void u64(std::uint64_t v);
  void f64(double v);
  void str(const std::string& v);
  Bytes take() { return std::move(bytes_); }

 private:
  Bytes bytes_;
};

class Reader {
 public:
  Reader(const unsigned char* data, std::size_t size) : data_(data), size_(size) {}
  explicit Reader(const Bytes& bytes) : Reader(bytes.data(), bytes.size()) {}
  std::uint8_t u8();
  std::uint32_t u32();
  std::uint64_t u64();
  double f64();
  std::string str();
  std::size_t remaining() const { return size_ - at_; }
  // Throws unless every byte was read.
  void finish() const;

 private:
  const unsigned char* take(std::size_t n);
  const unsigned char* data_;
  std::size_t size_;
  std::size_t at_ = 0;
};

}  // namespace tensegrity::sim::evolve::wire
