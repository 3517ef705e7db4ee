#include <joint_load_estimator/pipeline/timeline.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>

namespace jle {
namespace {

constexpr Stamp kReach = Stamp{1} << 52;  // [ns] of the time axis around its origin

}  // namespace

std::string secondsText(Stamp stamp) {
  char text[32];
  std::snprintf(text, sizeof text, "%.9f", static_cast<double>(stamp) * 1e-9);
  return text;
}

Timeline::Timeline(const Settings& settings)
    : threshold_(settings.time_jump_threshold),
      jump_confirm_(settings.stamps.jump_confirm),
      clock_(settings.stamps.regularize == StampRegularize::kAuto) {}

bool Timeline::zeroStamp(bool& stamped, Stamp& stamp, Stamp clock) {
  if (stamp != 0) {
    stamped = true;
    return true;
  }
  if (stamped) return false;
  stamp = clock;
  return true;
}

bool Timeline::clockWentBack(Stamp stamp, Stamp clock) {
  // The clock and the stamps come on different connections, so the clock may go back
  // one message after the stamps did (or before): a clock going back is a jump only
  // while the stamps do not go forward, else one jump would reset twice; going back
  // first, it confirms the stamps' jump back when they follow.
  const bool back = last_clock_ != 0 && clock < last_clock_;
  last_clock_ = clock;
  if (back) clock_back_ = jump_confirm_;
  return back && !(stamp > last_stamp_);
}

StampVerdict Timeline::jump(Stamp from, Stamp to) {
  jumped_ = true;
  jump_from_ = from;
  jump_to_ = to;
  return StampVerdict::kJump;
}

void Timeline::restart() {
  clock_.reset();
  last_stamp_ = 0;
  have_ref_ = axis_used_ = false;
  pending_ = clock_back_ = 0;
}

StampVerdict Timeline::checkJointStamp(Stamp stamp, Stamp clock, const std::string& topic,
                                       std::string& problem) {
  if (clockWentBack(stamp, clock)) return jump(last_stamp_, stamp);
  if (last_stamp_ == 0) {
    // The first joint state of the timeline, on an axis whose origin the wrenches or
    // plates set (and used) more than its reach away: their clock is another one (a
    // simulation's from 0 beside a wall clock). Kept, the axis would resolve these stamps
    // to no better than its rounding there (240 ns at 54 years) and take samples a few ns
    // apart for duplicates; the timeline restarts from the joint states, their readings
    // before it left behind (one warning, a jump in the diagnostics).
    if (axis_used_ && std::abs(stamp - time_ref_) > kReach) return jump(time_ref_, stamp);
    return StampVerdict::kOnTime;
  }
  const double ahead = static_cast<double>(stamp - last_stamp_) * 1e-9;
  // Forward, a gap of 10 periods is no jump either (a slow stream).
  const double forward = std::max(threshold_, 10e-9 * clock_.period());
  // A gap that the clock saw as well (a driver or a bag paused) keeps the stream's lag
  // behind the clock: no jump either.
  const double lag = static_cast<double>((stamp - clock) - (last_stamp_ - last_taken_clock_));
  if ((ahead >= -threshold_ && ahead <= forward) ||
      (ahead > 0.0 && std::abs(lag) * 1e-9 <= threshold_)) {
    pending_ = 0;
    return StampVerdict::kOnTime;
  }
  // On another timeline: a jump once jump_confirm in a row agree (in order, each within
  // `forward` of the one before), or at once back after the clock went back.
  const bool follows = pending_ > 0 && stamp > pending_stamp_ &&
                       static_cast<double>(stamp - pending_stamp_) * 1e-9 <= forward;
  pending_ = follows ? pending_ + 1 : 1;
  pending_stamp_ = stamp;
  if (pending_ >= jump_confirm_ || (ahead < 0.0 && clock_back_ > 0))
    return jump(last_stamp_, stamp);
  problem = topic + ": stamp " + secondsText(stamp) + " is " + std::to_string(ahead) +
            " s from the stream's (" + secondsText(last_stamp_) +
            "): dropped (a jump of time takes " + std::to_string(jump_confirm_) + " in a row)";
  return StampVerdict::kRogue;
}

StampVerdict Timeline::checkInputStamp(Stamp stamp, Stamp clock, double timeout,
                                       const std::string& input, std::string& problem) {
  if (clockWentBack(stamp, clock)) return jump(last_stamp_, stamp);
  if (last_stamp_ == 0) return StampVerdict::kOnTime;  // no joint sample on this timeline yet
  // The joint states may lag a reading that is on time by a few periods (a sensor whose
  // readings arrive before the joint states of their time): ten are allowed.
  const double ahead = static_cast<double>(stamp - last_stamp_) * 1e-9;
  if (ahead <= timeout + 1e-8 * clock_.period() && ahead >= -threshold_)
    return StampVerdict::kOnTime;
  problem = input + ": stamp " + secondsText(stamp) + " is " + std::to_string(ahead) +
            " s from the joint states' (" + secondsText(last_stamp_) + "): dropped";
  return StampVerdict::kRogue;
}

StampVerdict Timeline::order(Stamp stamp, Stamp assembling) const {
  const Stamp newest = std::max(last_stamp_, assembling);
  if (newest == 0 || stamp > newest) return StampVerdict::kOnTime;
  return stamp == newest ? StampVerdict::kDuplicate : StampVerdict::kOutOfOrder;
}

double Timeline::sampleTime(Stamp stamp) { return relative(clock_.add(stamp)); }

void Timeline::taken(Stamp stamp) {
  last_stamp_ = stamp;
  last_taken_clock_ = last_clock_;
  if (clock_back_ > 0) --clock_back_;
}

void Timeline::anchor(Stamp stamp) {
  // Under the estimator's samples a new origin would turn time back, and every later
  // sample would be refused as out of order; on the axis kept, times beyond the reach stay
  // in order and lose resolution slowly (2 ns to 104 days).
  if (have_ref_ && (axis_used_ || std::abs(stamp - time_ref_) <= kReach)) return;
  time_ref_ = stamp;
  have_ref_ = true;
}

double Timeline::relative(Stamp stamp) {
  anchor(stamp);
  axis_used_ = true;
  return static_cast<double>(stamp - time_ref_) * 1e-9;
}

Stamp Timeline::absolute(double t) const {
  return time_ref_ + static_cast<Stamp>(std::llround(t * 1e9));
}

}  // namespace jle
