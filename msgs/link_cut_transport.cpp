// SPDX-License-Identifier: Apache-2.0
#include "msgs/link_cut_transport.hpp"

#include <fastdds/rtps/transport/ChainingTransport.h>
#include <fastdds/rtps/transport/ChainingTransportDescriptor.h>

namespace tensegrity::msgs {

namespace rtps = eprosima::fastdds::rtps;
namespace frtps = eprosima::fastrtps::rtps;

namespace {

class LinkCutTransport final : public rtps::ChainingTransport {
 public:
  LinkCutTransport(const rtps::ChainingTransportDescriptor& descriptor, const std::atomic<bool>* cut,
                   const std::atomic<bool>* mute)
      : rtps::ChainingTransport(descriptor), cut_(cut), mute_(mute) {}

  // The UDP transport's own settings (buffer sizes, interfaces) are what Fast DDS asks for.
  rtps::TransportDescriptorInterface* get_configuration() override { return low_level_transport_->get_configuration(); }

  bool send(frtps::SenderResource* low_sender_resource, const frtps::octet* send_buffer, uint32_t send_buffer_size,
            frtps::LocatorsIterator* destination_locators_begin, frtps::LocatorsIterator* destination_locators_end,
            const std::chrono::steady_clock::time_point& timeout) override {
    // "Sent" as far as Fast DDS knows: a datagram lost on the air is not a local error.
    if (is_set(cut_) || is_set(mute_)) return true;
    return low_sender_resource->send(send_buffer, send_buffer_size, destination_locators_begin,
                                     destination_locators_end, timeout);
  }

  void receive(rtps::TransportReceiverInterface* next_receiver, const frtps::octet* receive_buffer,
               uint32_t receive_buffer_size, const frtps::Locator_t& local_locator,
               const frtps::Locator_t& remote_locator) override {
    if (is_set(cut_)) return;
    next_receiver->OnDataReceived(receive_buffer, receive_buffer_size, local_locator, remote_locator);
  }

 private:
  static bool is_set(const std::atomic<bool>* flag) { return flag != nullptr && flag->load(std::memory_order_relaxed); }
  const std::atomic<bool>* cut_;
  const std::atomic<bool>* mute_;
};

class LinkCutDescriptor final : public rtps::ChainingTransportDescriptor {
 public:
  LinkCutDescriptor(std::shared_ptr<rtps::TransportDescriptorInterface> low_level, const std::atomic<bool>* cut,
                    const std::atomic<bool>* mute)
      : rtps::ChainingTransportDescriptor(std::move(low_level)), cut_(cut), mute_(mute) {}
  rtps::TransportInterface* create_transport() const override { return new LinkCutTransport(*this, cut_, mute_); }

 private:
  const std::atomic<bool>* cut_;
  const std::atomic<bool>* mute_;
};

}  // namespace

std::shared_ptr<rtps::TransportDescriptorInterface> make_link_cut_transport(
    std::shared_ptr<rtps::TransportDescriptorInterface> low_level, const std::atomic<bool>* cut,
    const std::atomic<bool>* mute) {
  return std::make_shared<LinkCutDescriptor>(std::move(low_level), cut, mute);
}

}  // namespace tensegrity::msgs
