// SPDX-License-Identifier: Apache-2.0
#include "firmware/comms/node/node_dds.hpp"

namespace tensegrity::fw::comms {

void Participants::adopt(std::unique_ptr<NodeParticipant> fresh) {
  if (current_ != nullptr) {
    retire();  // an older one still listening: never more than two
    retiring_ = std::move(current_);
    std::lock_guard lock(retiring_->callback_mutex);
    retiring_->retiring = true;
  }
  current_ = std::move(fresh);
  pair(retiring_ != nullptr);
}

void Participants::pair(bool paired) noexcept {
  std::lock_guard lock(serial);  // no command listener is between its two acks
  if (current_ != nullptr) current_->peer = paired ? retiring_.get() : nullptr;
  if (retiring_ != nullptr) retiring_->peer = paired ? current_.get() : nullptr;
}

void Participants::retire() noexcept {
  if (retiring_ == nullptr) return;
  pair(false);
  retiring_->close();  // its listeners finish and are refused from then on
  retiring_.reset();
}

void Participants::close() noexcept {
  pair(false);
  // Entities deleted while current_ still points at them (reset() would null it first).
  if (current_ != nullptr) current_->close();
  current_.reset();
  retire();
}

}  // namespace tensegrity::fw::comms
