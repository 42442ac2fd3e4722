// SPDX-License-Identifier: Apache-2.0
// The operator console tests' fixture: a private folder for sockets and end caps
// 0-2 (comms_test_node) with a station that hears them.
#pragma once

#include <gtest/gtest.h>

#include <filesystem>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "ground/station.hpp"
#include "tests/ground/subprocess.hpp"

namespace tensegrity::ground {

class ConsoleLink : public ::testing::Test {
 protected:
  void SetUp() override {
    namespace fs = std::filesystem;
    dir_ = fs::temp_directory_path() / ("console_" + std::to_string(std::random_device{}()));
    fs::create_directories(dir_);
    fs::permissions(dir_, fs::perms::owner_all, fs::perm_options::replace);  // a console's folder is private
  }
  void TearDown() override {
    nodes_.reset();
    std::filesystem::remove_all(dir_);
  }
  // End caps 0-2 (comms_test_node) on `domain`, and a station that hears them; null
  // when either does not come up within 20 s.
  std::shared_ptr<Station> three_endcaps(int domain) {
    nodes_ = std::make_unique<test::Subprocess>(
        std::vector<std::string>{COMMS_TEST_NODE, "--domain", std::to_string(domain), "--endcaps", "0-2"},
        dir_ / "nodes.out", dir_ / "nodes.err");
    if (!nodes_->wait_for_output("READY", std::chrono::seconds(20))) return nullptr;
    StationOptions o;
    o.domain = domain;
    auto station = std::make_shared<Station>(o);
    if (!station->wait_for_endcaps(0b111, false, Station::now_ns() + 20'000'000'000)) return nullptr;
    return station;
  }
  std::filesystem::path dir_;
  std::unique_ptr<test::Subprocess> nodes_;
};

}  // namespace tensegrity::ground
