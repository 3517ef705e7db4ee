// csv_to_bag and bag_to_csv: a trial in joint_loads' CSV columns goes CSV -> bag ->
// process_bag (the node's message path) -> bag of JointLoads -> CSV, and the loads that
// come back are joint_loads' on the same CSV. The motion is a cubic polynomial in time
// and the wrench linear, so that a cubic Savitzky-Golay fit (the node's differentiator
// here) estimates q-dot and q-double-dot exactly up to rounding: any difference is a
// conversion's. The bag's contents are read back here with rosbag and compared with the
// CSV cell by cell.
#include <joint_load_estimator/JointLoads.h>
#include <joint_load_estimator/model/urdf_reader.hpp>

#include <geometry_msgs/WrenchStamped.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/JointState.h>
#include <tf2_msgs/TFMessage.h>

#include <jle_testing/tool_test.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <map>
#include <string>
#include <vector>

namespace {

using jle_test::Result;
using jle_test::Table;

const std::string kPanda = std::string(JLE_TEST_DATA) + "/urdf/panda.urdf";
constexpr int kRows = 200;             // 1 kHz: t = k / 1000 s
constexpr double kTimeOffset = 100.0;  // [s] stamps = t + 100 s
const char* const kWrenchLink = "panda_hand";

class CsvToBag : public jle_test::ToolTest {
 protected:
  CsvToBag() : ToolTest("jle_test_csv_to_bag") {}

  // A trial of the Panda: q_j(t) = a + b t + c t^2 + d t^3 with exact qd, qdd, and a
  // wrench at the hand linear in t. Returns the CSV's text.
  std::string trial() const {
    const jle::Model<double> model = jle::modelFromUrdfFile(kPanda);
    joints_ = model.coordinate_names;
    std::string text = "t";
    for (const std::string& j : joints_) text += "," + j + ".q," + j + ".qd," + j + ".qdd";
    for (const char* c : {"fx", "fy", "fz", "mx", "my", "mz"})
      text += std::string(",wrench@") + kWrenchLink + "." + c;
    text += "\n";
    for (int k = 0; k < kRows; ++k) {
      const double t = k / 1000.0;
      char cell[128];
      std::snprintf(cell, sizeof cell, "%.17g", t);
      text += cell;
      for (std::size_t j = 0; j < joints_.size(); ++j) {
        const double a = 0.1 * j - 0.3, b = 0.5 - 0.1 * j, c = 0.8 * std::cos(j),
                     d = -1.5 + 0.4 * j;
        const double q = a + t * (b + t * (c + t * d)), qd = b + t * (2 * c + 3 * d * t),
                     qdd = 2 * c + 6 * d * t;
        std::snprintf(cell, sizeof cell, ",%.17g,%.17g,%.17g", q, qd, qdd);
        text += cell;
      }
      for (int c = 0; c < 6; ++c) {
        std::snprintf(cell, sizeof cell, ",%.17g", (c + 1.0) * (1.0 - 2.0 * t) - 2.0);
        text += cell;
      }
      text += "\n";
    }
    return text;
  }

  Result tool(const char* program, const std::vector<std::string>& args) const {
    return ToolTest::run(program, args);
  }

  mutable std::vector<std::string> joints_;
};

std::int64_t ns(const ros::Time& t) { return static_cast<std::int64_t>(t.toNSec()); }

TEST_F(CsvToBag, TheBagHoldsTheCsvCellForCell) {
  write("trial.csv", trial());
  const Result r = tool(JLE_CSV_TO_BAG, {"--input", path("trial.csv"), "--output",
                                         path("out/trial.bag"), "--time-offset", "100"});
  ASSERT_EQ(r.status, 0) << r.err;
  const Table csv = jle_test::parseCsv(jle_test::readFile(path("trial.csv")));
  rosbag::Bag bag(path("out/trial.bag"));
  std::size_t joint_states = 0, wrenches = 0;
  for (const rosbag::MessageInstance& m : rosbag::View(bag)) {
    if (const auto js = m.instantiate<sensor_msgs::JointState>()) {
      const std::size_t k = joint_states++;
      EXPECT_EQ(ns(js->header.stamp), 100000000000LL + 1000000LL * static_cast<std::int64_t>(k));
      EXPECT_EQ(js->header.seq, k);
      EXPECT_EQ(js->name, joints_);
      ASSERT_EQ(js->position.size(), joints_.size());
      ASSERT_EQ(js->velocity.size(), joints_.size());
      for (std::size_t j = 0; j < joints_.size(); ++j) {
        EXPECT_EQ(js->position[j], csv.number(k, joints_[j] + ".q"));  // bit for bit
        EXPECT_EQ(js->velocity[j], csv.number(k, joints_[j] + ".qd"));
      }
    } else if (const auto w = m.instantiate<geometry_msgs::WrenchStamped>()) {
      EXPECT_EQ(m.getTopic(), std::string("/wrench/") + kWrenchLink);
      EXPECT_EQ(w->header.frame_id, kWrenchLink);
      const std::size_t k = wrenches++;
      const std::string p = std::string("wrench@") + kWrenchLink + ".";
      EXPECT_EQ(w->wrench.force.x, csv.number(k, p + "fx"));
      EXPECT_EQ(w->wrench.force.z, csv.number(k, p + "fz"));
      EXPECT_EQ(w->wrench.torque.y, csv.number(k, p + "my"));
    }
  }
  EXPECT_EQ(joint_states, static_cast<std::size_t>(kRows));
  EXPECT_EQ(wrenches, static_cast<std::size_t>(kRows));
}

// Receive-time stamps: each within [t + offset, t + offset + jitter), not all on the
// grid, and the same for the same seed.
TEST_F(CsvToBag, JitteredStampsAreSeededAndBounded) {
  write("trial.csv", trial());
  const auto stamps = [&](const char* seed, const char* name) {
    const Result r =
        tool(JLE_CSV_TO_BAG, {"--input", path("trial.csv"), "--output", path(name), "--time-offset",
                              "100", "--jitter", "0.0004", "--seed", seed});
    EXPECT_EQ(r.status, 0) << r.err;
    std::vector<std::int64_t> out;
    rosbag::Bag bag(path(name));
    for (const rosbag::MessageInstance& m : rosbag::View(bag, rosbag::TopicQuery("/joint_states")))
      out.push_back(ns(m.instantiate<sensor_msgs::JointState>()->header.stamp));
    return out;
  };
  const std::vector<std::int64_t> a = stamps("3", "out/a.bag"), b = stamps("3", "out/b.bag"),
                                  c = stamps("4", "out/c.bag");
  ASSERT_EQ(a.size(), static_cast<std::size_t>(kRows));
  EXPECT_EQ(a, b);
  EXPECT_NE(a, c);
  int off_grid = 0;
  for (std::size_t k = 0; k < a.size(); ++k) {
    const std::int64_t grid = 100000000000LL + 1000000LL * static_cast<std::int64_t>(k);
    EXPECT_GE(a[k], grid);
    EXPECT_LE(a[k], grid + 400000);
    off_grid += a[k] != grid;
  }
  EXPECT_GT(off_grid, kRows / 2);
  // A jitter beyond the spacing puts stamps out of order: refused, naming the line.
  const Result r =
      tool(JLE_CSV_TO_BAG, {"--input", path("trial.csv"), "--output", path("out/d.bag"),
                            "--time-offset", "100", "--jitter", "0.01"});
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("stamps do not increase"), std::string::npos) << r.err;
  // t = 0 without an offset is stamp 0, "unstamped" for ROS: refused.
  const Result zero =
      tool(JLE_CSV_TO_BAG, {"--input", path("trial.csv"), "--output", path("out/e.bag")});
  EXPECT_EQ(zero.status, 1);
  EXPECT_NE(zero.err.find("--time-offset"), std::string::npos) << zero.err;
}

// CSV -> bag -> process_bag -> bag of JointLoads -> bag_to_csv equals process_bag's own
// CSV and joint_loads on the first CSV at the published instants.
TEST_F(CsvToBag, TrialRoundTripsThroughTheNodesPath) {
  write("trial.csv", trial());
  write("config.yaml",
        "differentiator: {type: savitzky_golay, window: 7, order: 3, delay: 3}\n"
        "wrenches: [{topic: /wrench/panda_hand, link: panda_hand}]\n");
  ASSERT_EQ(tool(JLE_CSV_TO_BAG, {"--input", path("trial.csv"), "--output", path("out/in.bag"),
                                  "--time-offset", "100"})
                .status,
            0);
  const std::vector<std::string> common{"--bag", path("out/in.bag"), "--urdf",
                                        kPanda,  "--config",         path("config.yaml")};
  auto with = [&](std::vector<std::string> extra) {
    std::vector<std::string> args = common;
    args.insert(args.end(), extra.begin(), extra.end());
    return args;
  };
  Result r = tool(JLE_PROCESS_BAG, with({"--output", path("out/loads.bag")}));
  ASSERT_EQ(r.status, 0) << r.err;
  r = tool(JLE_PROCESS_BAG, with({"--csv", path("out/direct.csv"), "--kinematics"}));
  ASSERT_EQ(r.status, 0) << r.err;
  r = tool(JLE_BAG_TO_CSV,
           {"--bag", path("out/loads.bag"), "--output", path("out/back.csv"), "--kinematics"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(jle_test::readFile(path("out/back.csv")), jle_test::readFile(path("out/direct.csv")));

  r = tool(JLE_JOINT_LOADS,
           {"--urdf", kPanda, "--input", path("trial.csv"), "--output", path("out/reference.csv")});
  ASSERT_EQ(r.status, 0) << r.err;
  const Table back = jle_test::parseCsv(jle_test::readFile(path("out/back.csv")));
  const Table ref = jle_test::parseCsv(jle_test::readFile(path("out/reference.csv")));
  ASSERT_GE(back.rows.size(), static_cast<std::size_t>(kRows - 10));
  double worst = 0.0;
  for (std::size_t i = 0; i < back.rows.size(); ++i) {
    // The published stamp is the instant t + 100 s of row k.
    const double t = back.number(i, "t") - kTimeOffset;
    const long k = std::lround(t * 1000.0);
    ASSERT_NEAR(t, k / 1000.0, 1e-9);
    for (const std::string& j : joints_)
      for (const char* c : {".fx", ".fy", ".fz", ".mx", ".my", ".mz", ".effort"}) {
        const double d = std::abs(back.number(i, j + c) - ref.number(k, j + c));
        worst = std::max(worst, d);
        // The fit's rounding on stamps of 100 s (measured: 9e-11 N m at worst).
        EXPECT_LT(d, 1e-8) << "t " << t << " " << j << c;
      }
  }
  std::printf("round trip: worst |loads - joint_loads| %.3g (N or N m) over %zu rows\n", worst,
              back.rows.size());
}

TEST_F(CsvToBag, HelpAndBadInput) {
  for (const char* program : {JLE_CSV_TO_BAG, JLE_BAG_TO_CSV}) {
    const Result help = tool(program, {"--help"});
    EXPECT_EQ(help.status, 0);
    EXPECT_NE(help.out.find("Exit status"), std::string::npos);
    EXPECT_EQ(tool(program, {"--bogus"}).status, 2);
  }
  write("bad.csv", "t,a.q,a.qd,b.q\n1,0,0,0\n");
  const Result r =
      tool(JLE_CSV_TO_BAG, {"--input", path("bad.csv"), "--output", path("out/x.bag")});
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("JOINT.qd"), std::string::npos) << r.err;
  const Result none = tool(JLE_BAG_TO_CSV, {"--bag", path("out/x.bag")});
  EXPECT_EQ(none.status, 1);
}

}  // namespace
