// The time axis of the message path: the stamps of the joint states, wrenches and plates
// become the estimator's times [s] about an origin, and stamps that do not belong to the
// joint-state stream's timeline are told apart: a rogue stamp (dropped), or, confirmed, a
// jump of time (a looping bag, a restarted simulation, a driver's clock set). One part of
// the message path (pipeline.hpp): the Pipeline asks it about every message's stamp and,
// at a jump, resets what holds the old timeline's samples before the timeline restarts
// (docs/node.md, "Time stamps"). ROS-free; no allocation but a dropped message's words.
#pragma once

#include <joint_load_estimator/filters/sample_clock.hpp>
#include <joint_load_estimator/settings/config.hpp>

#include <cstdint>
#include <string>

namespace jle {

/// A message stamp [ns since the epoch]: a ROS header's sec * 1e9 + nsec.
using Stamp = std::int64_t;

/// A stamp in seconds to the nanosecond ("1700000000.123456789"), for messages.
std::string secondsText(Stamp stamp);

/// What a stamp is to the timeline.
enum class StampVerdict : std::uint8_t {
  kOnTime,  ///< on the timeline: the message goes on
  /// A jump of time: back (at once where the clock went back, else confirmed), or forward
  /// (confirmed). The caller takes or forgets what holds the old timeline's samples, then
  /// calls Timeline::restart(); the message goes on, on the new timeline.
  kJump,
  kRogue,       ///< far from the joint states' stamps and not a jump (yet): dropped
  kDuplicate,   ///< the stamp of the last joint sample taken (order())
  kOutOfOrder,  ///< older than it (order())
};

class Timeline {
 public:
  /// Reads time_jump_threshold, stamps.jump_confirm and stamps.regularize.
  explicit Timeline(const Settings& settings);

  /// Stamp 0: on a stream that has never had a stamp (`stamped` false: a live driver that
  /// stamps nothing) it becomes `clock`; on one that has, it is a rogue stamp (false): a
  /// bag's missing stamp is no reception time. A non-zero stamp sets `stamped`.
  static bool zeroStamp(bool& stamped, Stamp& stamp, Stamp clock);

  /// A joint state's stamp, and the front end's clock when it arrived (the node's
  /// ros::Time::now(), a bag's message time). More than time_jump_threshold back, or
  /// forward beyond it and beyond 10 periods while the clock did not move as far, it is on
  /// another timeline: kRogue (`problem` names `topic` and the stamp) until
  /// stamps.jump_confirm of them in a row agree, or at once back where the clock went back:
  /// kJump. The clock going back while the stamps do not go forward is a jump back too.
  StampVerdict checkJointStamp(Stamp stamp, Stamp clock, const std::string& topic,
                               std::string& problem);
  /// A wrench's or a plate's stamp: ahead of the last joint sample taken by more than
  /// `timeout` [s] (plus ten periods of the joint states), or behind it by more than
  /// time_jump_threshold, kRogue (`problem` names `input`); kJump where the clock went back
  /// (as checkJointStamp); kOnTime before the timeline's first joint sample.
  StampVerdict checkInputStamp(Stamp stamp, Stamp clock, double timeout, const std::string& input,
                               std::string& problem);
  /// After kJump: the new timeline, from the stamp that jumped. No joint sample is taken on
  /// it yet, its time axis has no origin, the sample clock starts again.
  void restart();

  /// A joint stamp against the last joint sample taken and `assembling` (the newest stamp
  /// of an instant still being assembled from several messages, or 0): kOnTime (newer than
  /// both), kDuplicate (equal to the newer) or kOutOfOrder.
  StampVerdict order(Stamp stamp, Stamp assembling = 0) const;
  /// The time [s] of a joint sample stamped `stamp` (in order): the sample clock's instant
  /// (stamps.regularize) on the time axis.
  double sampleTime(Stamp stamp);
  /// The joint sample stamped `stamp` was taken: the stream's stamps are checked against it.
  void taken(Stamp stamp);
  /// The stamp of the last joint sample taken on this timeline; 0 before its first.
  Stamp lastStamp() const { return last_stamp_; }

  /// The time axis resolves 1 ns within 2^52 ns (52 days) of its origin. anchor(): the
  /// first stamp sets the origin; a stamp farther away sets it again, but only while no
  /// time on it has been handed out (relative()) since the start or the last restart.
  void anchor(Stamp stamp);
  /// Seconds from the origin to `stamp` (anchored first).
  double relative(Stamp stamp);
  /// The stamp of time t [s] on the axis: the inverse of relative(), to the ns within 2^51
  /// ns (26 days) of the origin, within 1 ns out to its reach (test_timeline).
  Stamp absolute(double t) const;
  bool hasOrigin() const { return have_ref_; }
  Stamp origin() const { return time_ref_; }

  /// Whether the last check found a jump, from and to which stamps [ns] (from: the last
  /// joint sample taken, or the axis' origin where the joint states' first stamp is beyond
  /// its reach); clearJump() at each message.
  void clearJump() { jumped_ = false; }
  bool jumped() const { return jumped_; }
  Stamp jumpFrom() const { return jump_from_; }
  Stamp jumpTo() const { return jump_to_; }
  /// Whether that jump went forward (stamps far ahead, confirmed), not back.
  bool jumpedForward() const { return jumped_ && jump_from_ != 0 && jump_to_ > jump_from_; }

  /// The joint-state stream's sample clock (stamps.regularize).
  const SampleClock& sampleClock() const { return clock_; }

 private:
  bool clockWentBack(Stamp stamp, Stamp clock);
  StampVerdict jump(Stamp from, Stamp to);

  double threshold_;  // [s] time_jump_threshold
  int jump_confirm_;
  SampleClock clock_;
  // The time axis: seconds since the first stamp seen after the start or a restart (a
  // double holds epoch seconds only to 2.4e-7 s).
  Stamp time_ref_ = 0;
  bool have_ref_ = false;
  bool axis_used_ = false;  // a time on the axis was handed out (relative) since its origin
  Stamp last_stamp_ = 0;    // last joint sample taken (0 after a restart)
  Stamp last_clock_ = 0;
  Stamp last_taken_clock_ = 0;  // the clock when the last joint sample was taken
  // Joint states on another timeline, in a row: the last one's stamp and how many.
  Stamp pending_stamp_ = 0;
  int pending_ = 0;
  int clock_back_ = 0;  // joint samples taken since the clock went back that it confirms
  bool jumped_ = false;
  Stamp jump_from_ = 0, jump_to_ = 0;
};

}  // namespace jle
