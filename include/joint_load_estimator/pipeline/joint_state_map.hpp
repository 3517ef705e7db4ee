// Joint states, which may each carry a subset of the joints (several publishers), mapped
// onto the model's coordinates. ROS-free; the Pipeline's unit for it.
#pragma once

#include <joint_load_estimator/model/model.hpp>

#include <algorithm>
#include <string>
#include <vector>

namespace jle {

/// The latest position of every coordinate and the latest measured effort of every
/// published joint, from joint-state messages that may each carry a subset of the
/// joints. The name-to-index mapping is cached for the last layouts of names seen, so a
/// stream of messages with one layout (or a few, alternating: publishers that split the
/// joints) costs string comparisons and no allocation.
class JointStateMap {
 public:
  /// `published_segments` as publishedSegments() returns them; mimic_tolerance [rad or m]:
  /// how far a mimic joint's published position may be from its leader's (in the same
  /// message) times its multiplier plus its offset before it contradicts the model.
  JointStateMap(const Model<double>& model, const std::vector<int>& published_segments,
                double mimic_tolerance = 0.01);

  /// Binds the layout of a message's names (no cost but string comparisons for a layout
  /// among the last few): update() takes that message's values. Returns the index in
  /// `names` of the first name that an earlier entry has too, or -1 if every name is there
  /// once.
  int bind(const std::vector<std::string>& names);
  /// Takes the positions of the message whose names were bound last (same size, checked
  /// by the caller), its velocities and its efforts (each empty, or the same size; a
  /// non-finite one is taken as none: NaN). Mimic joints are ignored (a mimic follows its
  /// leader); one whose position contradicts its leader's in the same message is noted
  /// (mimicContradiction). Returns the index in the names of the first joint the model
  /// does not have, or -1 if there is none (the others are still taken).
  int update(const std::vector<double>& position, const std::vector<double>& velocity,
             const std::vector<double>& effort);
  /// The index in the last update()'s names of the first mimic joint whose position is
  /// more than mimic_tolerance from what its leader's gives (mimicExpected()), or -1.
  int mimicContradiction() const { return mimic_contradiction_; }
  /// What the model gives that mimic joint: multiplier times its leader's plus offset.
  double mimicExpected() const { return mimic_expected_; }

  /// Per entry of the last layout bound: the coordinate it
  /// sets (model.coordinate_names index), or -1 (a mimic, a fixed or unknown joint).
  const std::vector<int>& coordinates() const { return bindings_[current_].coordinate_of; }

  /// The positions, model.coordinate_names order (size nq).
  const std::vector<double>& q() const { return q_; }
  /// The velocities, model.coordinate_names order (size nq): a coordinate in the last
  /// message has its velocity there (NaN: none, or not finite); another keeps the value of
  /// the last message that had it (as its position), NaN before one.
  const std::vector<double>& qd() const { return qd_; }
  /// Whether coordinate k has had a position.
  bool received(int k) const { return received_[static_cast<std::size_t>(k)] != 0; }
  /// Whether coordinate k had a position in a message since the last clearFresh(): not,
  /// its position is held from an earlier message (another publisher's, an older one).
  bool fresh(int k) const { return fresh_[static_cast<std::size_t>(k)] != 0; }
  /// A sample was taken: every coordinate is held until a message sets it again.
  void clearFresh() { std::fill(fresh_.begin(), fresh_.end(), 0); }
  /// Index of the first coordinate with no position received yet, or -1 if none.
  int firstMissing() const;
  /// Latest measured effort per published joint (NaN until one is received).
  const std::vector<double>& effort() const { return effort_; }

 private:
  void checkMimics(const std::vector<double>& position);

  std::vector<std::string> coordinate_names_;
  std::vector<std::string> moving_joint_names_;  // every moving joint, mimics included
  // Per moving joint: its coordinate, and for a mimic its multiplier and offset (leader
  // false); per layout entry, the moving joint of a mimic (-1: none).
  std::vector<int> moving_coordinate_;
  std::vector<char> moving_is_mimic_;
  std::vector<double> moving_multiplier_, moving_offset_;
  double mimic_tolerance_ = 0.01;
  int mimic_contradiction_ = -1;
  double mimic_expected_ = 0.0;
  std::vector<std::string> published_joint_names_;
  std::vector<double> q_, qd_;
  std::vector<char> received_, fresh_;
  std::vector<double> effort_;
  // Cached bindings of the last kLayouts layouts of names (joint states split over
  // publishers alternate between theirs): per message index, the coordinate (-1: none: a
  // mimic or unknown), the published joint (-1: none), whether known, and the moving
  // joint of a mimic (-1: none); the first duplicated name. A layout seen again costs
  // string comparisons and no allocation.
  struct Binding {
    std::vector<std::string> layout;
    std::vector<int> coordinate_of, published_of, mimic_of;
    std::vector<char> known;
    int duplicate = -1;
    long used = -1;  // when last bound (-1: never)
  };
  static constexpr std::size_t kLayouts = 4;
  std::vector<Binding> bindings_ = std::vector<Binding>(kLayouts);
  std::size_t current_ = 0;
  long binds_ = 0;
};

}  // namespace jle
