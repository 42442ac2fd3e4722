// SPDX-License-Identifier: Apache-2.0
// TableInbox's decisions without DDS: samples are made with make_policy_message,
// the loop is the test taking from the mailbox and echoing in a Telemetry.
#include "firmware/comms/node/table_inbox.hpp"

#include <gtest/gtest.h>

#include <map>
#include <string>
#include <vector>

namespace tensegrity::fw::comms {
namespace {

constexpr int kEndcap = 3;
constexpr std::int64_t kAckTimeoutNs = 2'000'000'000;

// Blobs in memory; writes fail while `fail` is set.
class MemoryStorage final : public Storage {
 public:
  bool fail = false;
  int writes = 0;
  StorageResult read(std::string_view name, std::vector<std::uint8_t>& out) override {
    const auto it = blobs_.find(std::string(name));
    if (it == blobs_.end()) return StorageResult::not_found;
    out = it->second;
    return StorageResult::ok;
  }
  StorageResult write(std::string_view name, std::span<const std::uint8_t> data) override {
    if (fail) return StorageResult::io_error;
    ++writes;
    blobs_[std::string(name)].assign(data.begin(), data.end());
    return StorageResult::ok;
  }

 private:
  std::map<std::string, std::vector<std::uint8_t>> blobs_;
};

core::EndcapTable table_with(double value) {
  core::EndcapTable t;
  t.motor_count = 2;
  t.complexity = 4;
  t.period_s = 2.0;
  for (auto& motor : t.rest_length_m) motor.fill(value);
  return t;
}

PolicyTableMsg upload(std::uint32_t sequence, std::uint32_t version, double value = 0.8, bool force = false) {
  return make_policy_message(table_with(value), kEndcap, PolicyIdentity{"gait", version, "superball", force}, sequence);
}

struct Reply {
  std::uint32_t sequence;
  PolicyReason reason;
  std::string text;
};

class TableInboxTest : public ::testing::Test {
 protected:
  TableInboxTest() {
    expect_.robot = "superball";
    expect_.endcap_id = kEndcap;
  }

  TableInbox make(app::PolicyStore* store) {
    return TableInbox(
        expect_, kAckTimeoutNs, store,
        [this](const PolicyTableMsg& msg, PolicyReason reason, const std::string& text) {
          replies.push_back({msg.upload_sequence(), reason, text});
        },
        log_);
  }
  // The loop: takes what was handed over and echoes it, with `error`.
  bool loop_takes(TableInbox& inbox, core::TableError error = core::TableError::none) {
    app::HostTable taken;
    if (!inbox.take(taken)) return false;
    loop_.table_ack_sequence = taken.sequence;
    loop_.table_ack_error = error;
    return true;
  }

  PolicyExpectations expect_;
  NodeLog log_{kEndcap, false};
  app::Telemetry loop_{};
  std::vector<Reply> replies;
};

TEST_F(TableInboxTest, AcceptedOnlyOnceTheLoopTookIt) {
  TableInbox inbox = make(nullptr);
  inbox.offer(upload(1, 1));
  inbox.poll(0, &loop_);
  EXPECT_TRUE(replies.empty()) << "answered before the loop took it";
  EXPECT_TRUE(inbox.awaiting_loop());
  ASSERT_TRUE(loop_takes(inbox));
  inbox.poll(1'000'000, &loop_);
  ASSERT_EQ(replies.size(), 1U);
  EXPECT_EQ(replies[0].reason, PolicyReason::accepted);
  EXPECT_EQ(inbox.active().policy_id, "gait");
  EXPECT_EQ(inbox.active().policy_version, 1U);
  EXPECT_FALSE(inbox.awaiting_loop());
}

TEST_F(TableInboxTest, AnotherEndcapsTableIsIgnored) {
  TableInbox inbox = make(nullptr);
  inbox.offer(make_policy_message(table_with(0.8), kEndcap + 1, PolicyIdentity{"gait", 1, "superball", false}, 1));
  inbox.poll(0, &loop_);
  app::HostTable taken;
  EXPECT_FALSE(inbox.take(taken));
  EXPECT_TRUE(replies.empty());
}

TEST_F(TableInboxTest, StoredBeforeHandedOverAndRestoredWhenTheLoopRefuses) {
  MemoryStorage storage;
  app::PolicyStore store(storage, 2, expect_.limits);
  TableInbox inbox = make(&store);
  inbox.offer(upload(1, 1, 0.8));
  inbox.poll(0, &loop_);
  ASSERT_TRUE(loop_takes(inbox));
  inbox.poll(0, &loop_);
  ASSERT_EQ(replies.back().reason, PolicyReason::accepted);

  inbox.offer(upload(2, 2, 0.9));
  inbox.poll(0, &loop_);
  app::StoredTable stored;
  ASSERT_TRUE(store.current(stored));
  EXPECT_EQ(stored.identity.policy_version, 2U) << "handed to the loop before it was durable";
  ASSERT_TRUE(loop_takes(inbox, core::TableError::bad_period));
  inbox.poll(0, &loop_);
  EXPECT_FALSE(is_accepted(replies.back().reason));
  ASSERT_TRUE(store.current(stored));
  EXPECT_EQ(stored.identity.policy_version, 1U) << "the refused table stayed in storage";
  EXPECT_DOUBLE_EQ(stored.table.rest_length_m[0][0], 0.8);
  EXPECT_EQ(inbox.active().policy_version, 1U);
}

TEST_F(TableInboxTest, AStorageFailureIsAnsweredAndNothingReachesTheLoop) {
  MemoryStorage storage;
  app::PolicyStore store(storage, 2, expect_.limits);
  storage.fail = true;
  TableInbox inbox = make(&store);
  inbox.offer(upload(1, 1));
  inbox.poll(0, &loop_);
  ASSERT_EQ(replies.size(), 1U);
  EXPECT_EQ(replies[0].reason, PolicyReason::storage_failed);
  app::HostTable taken;
  EXPECT_FALSE(inbox.take(taken));
  // Transient: the same upload is judged again, not answered from memory.
  storage.fail = false;
  inbox.offer(upload(1, 1));
  inbox.poll(0, &loop_);
  EXPECT_TRUE(inbox.take(taken));
}

TEST_F(TableInboxTest, ASlowLoopIsAnsweredBusyAndTheTableIsAcceptedLate) {
  TableInbox inbox = make(nullptr);
  inbox.offer(upload(1, 1));
  inbox.poll(0, &loop_);
  inbox.poll(kAckTimeoutNs, &loop_);
  EXPECT_TRUE(replies.empty()) << "busy before the timeout";
  inbox.poll(kAckTimeoutNs + 1, &loop_);
  ASSERT_EQ(replies.size(), 1U);
  EXPECT_EQ(replies[0].reason, PolicyReason::loop_busy);
  // Meanwhile another table waits for none: one in flight at a time.
  inbox.offer(upload(2, 2));
  inbox.poll(kAckTimeoutNs + 2, &loop_);
  ASSERT_EQ(replies.size(), 2U);
  EXPECT_EQ(replies[1].sequence, 2U);
  EXPECT_EQ(replies[1].reason, PolicyReason::loop_busy);
  ASSERT_TRUE(loop_takes(inbox));
  inbox.poll(kAckTimeoutNs + 3, &loop_);
  ASSERT_EQ(replies.size(), 3U);
  EXPECT_EQ(replies[2].reason, PolicyReason::accepted);
  EXPECT_EQ(inbox.active().policy_version, 1U);
}

TEST_F(TableInboxTest, ARetryGetsTheSameAnswerAndAReusedSequenceIsJudgedAnew) {
  TableInbox inbox = make(nullptr);
  inbox.offer(upload(1, 1));
  inbox.poll(0, &loop_);
  ASSERT_TRUE(loop_takes(inbox));
  inbox.poll(0, &loop_);
  inbox.offer(upload(1, 1));
  inbox.poll(0, &loop_);
  ASSERT_EQ(replies.size(), 2U);
  EXPECT_EQ(replies[1].reason, PolicyReason::accepted);
  app::HostTable taken;
  EXPECT_FALSE(inbox.take(taken)) << "a retry reached the loop again";
  // Sequence 1 again, other content: judged (stale, version 1 is active).
  inbox.offer(upload(1, 1, 0.9));
  inbox.poll(0, &loop_);
  EXPECT_EQ(replies.back().reason, PolicyReason::stale_version);
}

TEST_F(TableInboxTest, TheActiveOneIsAlreadyActiveAndOlderOnesNeedForce) {
  TableInbox inbox = make(nullptr);
  inbox.offer(upload(1, 5));
  inbox.poll(0, &loop_);
  ASSERT_TRUE(loop_takes(inbox));
  inbox.poll(0, &loop_);
  inbox.offer(upload(2, 5));
  inbox.poll(0, &loop_);
  EXPECT_EQ(replies.back().reason, PolicyReason::already_active);
  inbox.offer(upload(3, 4, 0.9));
  inbox.poll(0, &loop_);
  EXPECT_EQ(replies.back().reason, PolicyReason::stale_version);
  inbox.offer(upload(4, 4, 0.9, true));
  inbox.poll(0, &loop_);
  EXPECT_TRUE(loop_takes(inbox)) << "a forced older version was not handed over";
}

TEST_F(TableInboxTest, AFullInboxAnswersBusyAndACopyIsTakenOnce) {
  TableInbox inbox = make(nullptr);
  inbox.offer(upload(1, 1));
  inbox.poll(0, &loop_);  // in flight: the rest wait in the inbox
  for (std::uint32_t s = 2; s < 2 + TableInbox::kCapacity; ++s) inbox.offer(upload(s, s));
  inbox.offer(upload(2, 2));  // a copy (both participants took it): dropped silently
  EXPECT_TRUE(replies.empty());
  inbox.offer(upload(99, 99));
  ASSERT_EQ(replies.size(), 1U);
  EXPECT_EQ(replies[0].sequence, 99U);
  EXPECT_EQ(replies[0].reason, PolicyReason::loop_busy);
}

TEST_F(TableInboxTest, AFormatErrorIsRefusedWithItsReason) {
  TableInbox inbox = make(nullptr);
  PolicyTableMsg msg = upload(1, 1);
  msg.checksum(msg.checksum() + 1);
  inbox.offer(msg);
  inbox.poll(0, &loop_);
  ASSERT_EQ(replies.size(), 1U);
  EXPECT_EQ(replies[0].reason, PolicyReason::bad_checksum);
}

TEST_F(TableInboxTest, TheStoredRecordIsTheActivePolicyAtStart) {
  MemoryStorage storage;
  app::PolicyStore store(storage, 2, expect_.limits);
  std::string error;
  ASSERT_EQ(store.save(table_with(0.8), {"kept", 4, 77}, error), StorageResult::ok) << error;
  TableInbox inbox = make(&store);
  EXPECT_EQ(inbox.active().policy_id, "kept");
  EXPECT_EQ(inbox.active().policy_version, 4U);
}

}  // namespace
}  // namespace tensegrity::fw::comms
