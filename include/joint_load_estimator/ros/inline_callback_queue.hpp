// A callback queue that queues nothing: the node's input subscriptions with
// inline_callbacks (config.hpp, Settings::inline_callbacks).
#pragma once

#include <ros/callback_queue_interface.h>

#include <cstdint>
#include <thread>

namespace jle {

/// Calls every callback at once, in the thread that adds it. For a subscription that is
/// the thread delivering the message: the publisher's own thread for a publisher in the
/// same process (a driver in the same nodelet manager), roscpp's network thread for a
/// TCP connection. It saves the hand-over to a spinner or nodelet worker thread (a
/// wake-up, the largest part of the latency on a loaded machine); the callbacks then
/// run in foreign threads, so they must be short and serialise themselves (a
/// subscription using it is made with allow_concurrent_callbacks, and the node's
/// callbacks take one mutex).
class InlineCallbackQueue : public ros::CallbackQueueInterface {
 public:
  void addCallback(const ros::CallbackInterfacePtr& callback, uint64_t /*owner_id*/) override {
    // TryAgain: the callback is not ready yet (its subscription busy in another thread).
    while (callback->call() == ros::CallbackInterface::TryAgain) std::this_thread::yield();
  }
  void removeByID(uint64_t /*owner_id*/) override {}
};

}  // namespace jle
