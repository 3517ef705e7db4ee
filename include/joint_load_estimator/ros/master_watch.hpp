// Whether the ROS master this node registered with is still the one running: roscpp
// registers a node's topics and services once, at start, and a restarted roscore knows
// none of them (no new publisher connects, the node is silently deaf to it). Fed by the
// node's wall timer with what it polls (ros::master::check() and the master's /run_id);
// the decision is here, testable without a master.
#pragma once

#include <string>
#include <utility>

namespace jle {

class MasterWatch {
 public:
  /// What changed at a poll.
  enum class Event {
    kNone,
    kLost,      ///< the master stopped answering
    kBack,      ///< it answers again with the run_id it had: the same master, nothing lost
    kRestarted  ///< another master answers (a new run_id, or none to compare): unregistered
  };

  /// `run_id`: the master's /run_id when the node registered (empty: unknown).
  explicit MasterWatch(std::string run_id) : run_id_(std::move(run_id)) {}

  /// A poll: whether the master answered, and its /run_id then (empty: unknown).
  Event update(bool reachable, const std::string& run_id) {
    if (!reachable) {
      const bool lost = reachable_;
      reachable_ = false;
      unknown_polls_ = 0;
      return lost ? Event::kLost : Event::kNone;
    }
    // The node started before roscore set /run_id: the first one read is its master's.
    if (reachable_ && run_id_.empty() && !run_id.empty()) {
      run_id_ = run_id;
      return Event::kNone;
    }
    const bool changed = !run_id.empty() && !run_id_.empty() && run_id != run_id_;
    if (reachable_ && !changed) return Event::kNone;
    // Back after a loss without a run_id yet (roscore sets /run_id a moment after its
    // master answers): decided at a later poll, or after kUnknownPolls without one.
    if (!reachable_ && run_id.empty() && !run_id_.empty() && ++unknown_polls_ < kUnknownPolls)
      return Event::kNone;
    reachable_ = true;
    unknown_polls_ = 0;
    previous_ = run_id_;
    const bool same = !run_id.empty() && run_id == run_id_;
    run_id_ = run_id;
    return same ? Event::kBack : Event::kRestarted;
  }

  /// The run_id before the last kRestarted, and now (empty: unknown).
  const std::string& previousRunId() const { return previous_; }
  const std::string& runId() const { return run_id_; }

 private:
  static constexpr int kUnknownPolls = 3;
  std::string run_id_, previous_;
  bool reachable_ = true;
  int unknown_polls_ = 0;  // polls answered without a run_id since the master came back
};

}  // namespace jle
