// SPDX-License-Identifier: Apache-2.0
#include "sim/evolve/mpi_wire.hpp"

#include <bit>

namespace tensegrity::sim::evolve::wire {
namespace {

// A count of n elements of at least `each` bytes must fit in what is left: a damaged
// count is reported, not turned into a gigabyte allocation.
std::size_t count(Reader& r, std::size_t each) {
  const std::uint64_t n = r.u64();
  if (n > r.remaining() / each) throw WireError("count " + std::to_string(n) + " exceeds the message");
  return static_cast<std::size_t>(n);
}

void team(Writer& w, const Team& t) {
  w.u64(t.rest_lengths_m.size());
  for (const auto& values : t.rest_lengths_m) {
    w.u64(values.size());
    for (double v : values) w.f64(v);
  }
}

Team team(Reader& r) {
  Team t;
  t.rest_lengths_m.resize(count(r, 8));
  for (auto& values : t.rest_lengths_m) {
    values.resize(count(r, 8));
    for (double& v : values) v = r.f64();
  }
  return t;
}

template <typename Decode>
auto decode(const Bytes& bytes, const char* what, Decode body) {
  try {
    Reader r(bytes);
    auto m = body(r);
    r.finish();
    return m;
  } catch (const WireError& e) {
    throw WireError(std::string(what) + " message: " + e.what());
  }
}

}  // namespace

const char* to_string(Tag tag) {
  switch (tag) {
    case Tag::setup: return "setup";
    case Tag::hello: return "hello";
    case Tag::job: return "job";
    case Tag::result: return "result";
    case Tag::stop: return "stop";
  }
  return "unknown";
}

void Writer::u32(std::uint32_t v) {
  for (int i = 0; i < 4; ++i) bytes_.push_back(static_cast<unsigned char>(v >> (8 * i)));
}

void Writer::u64(std::uint64_t v) {
  for (int i = 0; i < 8; ++i) bytes_.push_back(static_cast<unsigned char>(v >> (8 * i)));
}

void Writer::f64(double v) { u64(std::bit_cast<std::uint64_t>(v)); }

void Writer::str(const std::string& v) {
  u64(v.size());
  bytes_.insert(bytes_.end(), v.begin(), v.end());
}

const unsigned char* Reader::take(std::size_t n) {
  if (n > size_ - at_) throw WireError("truncated");
  const unsigned char* p = data_ + at_;
  at_ += n;
  return p;
}

std::uint8_t Reader::u8() { return *take(1); }

std::uint32_t Reader::u32() {
  const unsigned char* p = take(4);
  std::uint32_t v = 0;
  for (int i = 0; i < 4; ++i) v |= static_cast<std::uint32_t>(p[i]) << (8 * i);
  return v;
}

std::uint64_t Reader::u64() {
  const unsigned char* p = take(8);
  std::uint64_t v = 0;
  for (int i = 0; i < 8; ++i) v |= static_cast<std::uint64_t>(p[i]) << (8 * i);
  return v;
}

double Reader::f64() { return std::bit_cast<double>(u64()); }

std::string Reader::str() {
  const std::uint64_t n = u64();
  if (n > remaining()) throw WireError("string of " + std::to_string(n) + " bytes exceeds the message");
  const unsigned char* p = take(static_cast<std::size_t>(n));
  return std::string(reinterpret_cast<const char*>(p), static_cast<std::size_t>(n));
}

void Reader::finish() const {
  if (at_ != size_) throw WireError(std::to_string(size_ - at_) + " trailing bytes");
}

Bytes encode(const Setup& m) {
  Writer w;
  w.u32(m.protocol);
  w.str(m.kind);
  w.str(m.payload);
  return w.take();
}

Bytes encode(const Hello& m) {
  Writer w;
  w.u32(m.protocol);
  w.u32(static_cast<std::uint32_t>(m.threads));
  w.str(m.host);
  w.str(m.build);
  w.str(m.error);
  return w.take();
}

Bytes encode(const Job& m) {
  Writer w;
  w.u64(m.batch);
  w.u64(m.index);
  team(w, m.team);
  return w.take();
}

Bytes encode(const Result& m) {
  Writer w;
  w.u64(m.batch);
  w.u64(m.index);
  w.f64(m.result.score_m);
  w.u8(m.result.feasible ? 1 : 0);
  w.str(m.error);
  return w.take();
}

Setup decode_setup(const Bytes& bytes) {
  return decode(bytes, "setup", [](Reader& r) {
    Setup m;
    m.protocol = r.u32();
    m.kind = r.str();
    m.payload = r.str();
    return m;
  });
}

Hello decode_hello(const Bytes& bytes) {
  return decode(bytes, "hello", [](Reader& r) {
    Hello m;
    m.protocol = r.u32();
    m.threads = static_cast<std::int32_t>(r.u32());
    m.host = r.str();
    m.build = r.str();
    m.error = r.str();
    return m;
  });
}

Job decode_job(const Bytes& bytes) {
  return decode(bytes, "job", [](Reader& r) {
    Job m;
    m.batch = r.u64();
    m.index = r.u64();
    m.team = team(r);
    return m;
  });
}

Result decode_result(const Bytes& bytes) {
  return decode(bytes, "result", [](Reader& r) {
    Result m;
    m.batch = r.u64();
    m.index = r.u64();
    m.result.score_m = r.f64();
    const std::uint8_t feasible = r.u8();
    if (feasible > 1) throw WireError("feasible flag " + std::to_string(feasible));
    m.result.feasible = feasible == 1;
    m.error = r.str();
    return m;
  });
}

}  // namespace tensegrity::sim::evolve::wire
