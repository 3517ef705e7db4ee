// What each input topic of the node has delivered since the last diagnosis: how many
// messages, how many the pipeline used, how many its publishers sent that never arrived
// (header.seq gaps: lost in transport or in a full subscription queue), and when the
// last one came. ROS-free but for the wall clock the node hands in.
#pragma once

#include <joint_load_estimator/pipeline/pipeline.hpp>

#include <cstdint>
#include <string>
#include <unordered_map>
#include <utility>

namespace jle {

/// One input topic's counts, kept by the node per message (InputHealth::take) and read
/// by its diagnostics (InputHealth::since), which also restart the period.
class InputHealth {
 public:
  /// The counts of one diagnostics period.
  struct Period {
    long received = 0;  ///< messages taken
    long used = 0;      ///< of those, used by the pipeline (not dropped)
    long lost = 0;      ///< messages the publishers numbered but that never arrived
    Outcome last_drop = Outcome::kUsed;  ///< why the last dropped one was dropped
  };

  explicit InputHealth(std::string topic = "") : topic_(std::move(topic)) {}

  /// A message of `publisher` (its caller id) numbered `seq` (header.seq), received at
  /// `wall_s` [s], with the pipeline's outcome. roscpp and rospy number every message
  /// of a topic they send; a message handed over in-process keeps the sender's seq (0,
  /// often). A publisher that leaves seq at 0 or restarts its numbering loses nothing.
  void take(const std::string& publisher, std::uint32_t seq, Outcome outcome, double wall_s);

  /// Whether `outcome` drops the message (the pipeline did not take it): invalid, stamp
  /// order, frame, base pose, no needed joint.
  static bool dropped(Outcome outcome);

  /// The counts since the last call (or the start); starts the next period.
  Period since();
  /// Totals since the start.
  long received() const { return received_; }
  long lost() const { return lost_; }
  /// [s] wall time of the last message; 0: none yet.
  double lastReceived() const { return last_wall_s_; }
  const std::string& topic() const { return topic_; }

 private:
  std::string topic_;
  long received_ = 0, used_ = 0, lost_ = 0;
  Period at_last_;  // the totals at the last since()
  Outcome last_drop_ = Outcome::kUsed;
  double last_wall_s_ = 0.0;
  std::unordered_map<std::string, std::uint32_t> last_seq_;  // per publisher
};

}  // namespace jle
