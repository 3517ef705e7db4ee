#include <joint_load_estimator/ros/input_health.hpp>

namespace jle {

bool InputHealth::dropped(Outcome outcome) {
  switch (outcome) {
    case Outcome::kInvalid:
    case Outcome::kOrder:
    case Outcome::kFrame:
    case Outcome::kNoBasePose:
    case Outcome::kRogueStamp:
    case Outcome::kNoJoint: return true;
    default: return false;
  }
}

void InputHealth::take(const std::string& publisher, std::uint32_t seq, Outcome outcome,
                       double wall_s) {
  ++received_;
  if (dropped(outcome))
    last_drop_ = outcome;
  else
    ++used_;
  last_wall_s_ = wall_s;
  if (last_seq_.size() > 64) last_seq_.clear();  // bounded: publishers come and go
  const auto it = last_seq_.find(publisher);
  if (it == last_seq_.end()) {
    last_seq_.emplace(publisher, seq);
    return;
  }
  // A gap of the numbering is a loss; a repeat or a step back is a restarted publisher.
  if (seq > it->second) lost_ += static_cast<long>(seq - it->second - 1);
  it->second = seq;
}

InputHealth::Period InputHealth::since() {
  Period p;
  p.received = received_ - at_last_.received;
  p.used = used_ - at_last_.used;
  p.lost = lost_ - at_last_.lost;
  p.last_drop = last_drop_;
  at_last_.received = received_;
  at_last_.used = used_;
  at_last_.lost = lost_;
  return p;
}

}  // namespace jle
