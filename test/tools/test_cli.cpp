// The command-line tools joint_loads and make_trajectory, run as processes: their CSV
// plumbing (column mapping, order, frames, number formatting), their refusal of bad
// input with one located message and no output file, and make_trajectory's formula;
// and the option values' parsers that every tool shares (command_line.hpp).
#include <joint_load_estimator/io/command_line.hpp>
#include <joint_load_estimator/model/dynamics.hpp>
#include <joint_load_estimator/model/kinematics.hpp>
#include <joint_load_estimator/model/urdf_reader.hpp>

#include <jle_testing/tool_test.hpp>

#include <gtest/gtest.h>
#include <urdf/model.h>
#include <yaml-cpp/yaml.h>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <map>
#include <random>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;

const std::string kData = JLE_TEST_DATA;
const std::string kPandaChain = kData + "/urdf/chains/panda_chain.urdf";
const std::string kPanda = kData + "/urdf/panda.urdf";

using jle_test::Result;
using jle_test::Table;
using jle_test::readFile;
using jle_test::writeFile;

Table parseTable(const std::string& text) { return jle_test::parseCsv(text); }

std::string formatTable(const Table& table, const std::string& end_of_line = "\n") {
  const auto join = [&](const std::vector<std::string>& cells) {
    std::string line;
    for (std::size_t i = 0; i < cells.size(); ++i) line += (i ? "," : "") + cells[i];
    return line + end_of_line;
  };
  std::string text = join(table.header);
  for (const auto& row : table.rows) text += join(row);
  return text;
}

// One temporary directory per test: inputs and captured streams at the top, the tools'
// outputs in out/, which must stay empty whenever a tool fails.
class CliTest : public jle_test::ToolTest {
 protected:
  CliTest() : ToolTest("jle_test_cli") {}

  std::string outPath() const { return outDir() + "/loads.csv"; }

  Result jointLoads(const std::vector<std::string>& args) const {
    return run(JLE_JOINT_LOADS, args);
  }
  Result makeTrajectory(const std::vector<std::string>& args) const {
    return run(JLE_MAKE_TRAJECTORY, args);
  }

  // make_trajectory into `name`; fails the test if it fails.
  std::string trajectory(const std::string& name, const std::string& urdf,
                         std::vector<std::string> args) const {
    args.insert(args.begin(), {"--urdf", urdf, "--output", path(name)});
    const Result r = makeTrajectory(args);
    EXPECT_EQ(r.status, 0) << r.err;
    return path(name);
  }

  std::vector<std::string> outEntries() const {
    std::vector<std::string> names;
    for (const auto& e : fs::directory_iterator(outDir())) names.push_back(e.path().string());
    return names;
  }
};

// ------------------------------------------------------------------ the library's answer

std::vector<std::string> loadHeader(const std::vector<std::string>& joints) {
  std::vector<std::string> names{"t"};
  for (const std::string& j : joints)
    for (const char* s : {"fx", "fy", "fz", "mx", "my", "mz", "effort"})
      names.push_back(j + "." + s);
  return names;
}

std::vector<std::string> pandaArm() {
  std::vector<std::string> joints;
  for (int i = 1; i <= 7; ++i) joints.push_back("panda_joint" + std::to_string(i));
  return joints;
}

// Checks every output row of joint_loads against the library run on the same input
// row: joint wrench (named by the output column) in `frame`, effort.
void expectMatchesLibrary(const std::string& urdf, const Table& in, const Table& out,
                          const std::vector<std::string>& joints, const std::string& wrench_link,
                          jle::WrenchFrame frame, const Eigen::Vector3d& gravity) {
  const jle::Model<double> model = jle::modelFromUrdfFile(urdf);
  jle::Data<double> data(model);
  ASSERT_EQ(out.header, loadHeader(joints));
  ASSERT_EQ(out.rows.size(), in.rows.size());
  jle::VectorX<double> q(model.nq), qd(model.nq), qdd(model.nq);
  for (std::size_t r = 0; r < in.rows.size(); ++r) {
    for (int k = 0; k < model.nq; ++k) {
      const std::string& name = model.coordinate_names[k];
      q[k] = in.number(r, name + ".q");
      qd[k] = in.number(r, name + ".qd");
      qdd[k] = in.number(r, name + ".qdd");
    }
    jle::forwardKinematics(model, data, q, qd, qdd, gravity);
    if (!wrench_link.empty()) {
      const std::string w = "wrench@" + wrench_link + ".";
      jle::addExternalWrench(
          model, data, model.frameIndex(wrench_link),
          Eigen::Vector3d(in.number(r, w + "fx"), in.number(r, w + "fy"), in.number(r, w + "fz")),
          Eigen::Vector3d(in.number(r, w + "mx"), in.number(r, w + "my"), in.number(r, w + "mz")),
          jle::WrenchFrame::kLocal);
    }
    jle::inverseDynamics(model, data);

    ASSERT_EQ(out.rows[r].size(), out.header.size()) << "row " << r;
    // t passes through unchanged: the same 17 digits in and out.
    EXPECT_EQ(out.rows[r][0], in.rows[r][in.column("t")]);
    for (std::size_t c = 0; c < out.header.size(); ++c) {
      const std::string& cell = out.rows[r][c];
      const double printed = std::strtod(cell.c_str(), nullptr);
      // The text is exactly %.17g of the number it reads back as: 17 significant digits.
      char canonical[40];
      std::snprintf(canonical, sizeof canonical, "%.17g", printed);
      EXPECT_EQ(cell, canonical) << out.header[c] << " row " << r;
      if (c == 0) continue;

      const std::string& column = out.header[c];
      const std::size_t dot = column.rfind('.');
      const int s = model.segmentOfJoint(column.substr(0, dot));
      const std::string component = column.substr(dot + 1);
      const jle::Wrench<double> w = jle::jointWrench(model, data, s, frame);
      double expected = data.effort[s];
      if (component != "effort") {
        const Eigen::Vector3d& v = component[0] == 'f' ? w.force : w.moment;
        expected = v[component[1] - 'x'];
      }
      // The same algorithm on the same doubles (the inputs' 17 digits read back exactly):
      // a column mix-up or a wrong frame is off by newtons. 1e-12 relative leaves room only
      // for a compiler contracting a*b+c differently in the two builds.
      EXPECT_NEAR(printed, expected, 1e-12 * std::max(1.0, std::abs(expected)))
          << column << " row " << r;
#ifndef __FP_FAST_FMA
      // Without fused multiply-add both builds round identically: the printed 17 digits
      // must give back the library's double bit for bit.
      EXPECT_EQ(printed, expected) << column << " row " << r;
#endif
    }
  }
}

// ------------------------------------------------------------------ round trips

TEST_F(CliTest, PandaChainRoundTripMatchesTheLibrary) {
  const std::string in =
      trajectory("states.csv", kPandaChain,
                 {"--duration", "0.05", "--rate", "1000", "--seed", "7", "--wrench", "panda_hand"});
  const Result r = jointLoads({"--urdf", kPandaChain, "--input", in, "--output", outPath()});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.err, "");
  const Table input = parseTable(readFile(in));
  ASSERT_EQ(input.rows.size(), 51u);  // t = 0, 0.001, ..., 0.05
  expectMatchesLibrary(kPandaChain, input, parseTable(readFile(outPath())), pandaArm(),
                       "panda_hand", jle::WrenchFrame::kChild, Eigen::Vector3d(0, 0, -9.80665));

  // Without --output the same bytes go to standard output.
  const Result piped = jointLoads({"--urdf", kPandaChain, "--input", in});
  ASSERT_EQ(piped.status, 0) << piped.err;
  EXPECT_EQ(piped.out, readFile(outPath()));
}

// identified_pendulum.urdf (test/data/urdf/SOURCE.md): its links' inertias no rigid body
// has ('arm' not positive semi-definite, 'hand' breaking the triangle inequality).
// Refused by default (exit 1, link and violation named); with
// --accept-nonphysical-inertia the loads are written, a warning names each link and
// violation, and the effort about the axis is the closed form 1.81 qdd - 2 g cos q
// (ixx and izz do not enter).
TEST_F(CliTest, IdentifiedInertiaNeedsTheFlag) {
  const std::string urdf = kData + "/urdf/identified_pendulum.urdf";
  write("states.csv",
        "t,shoulder.q,shoulder.qd,shoulder.qdd\n0,0,0,0\n0.01,0.7,1.3,-0.4\n0.02,-2.1,-0.5,3\n");
  const Result refused =
      jointLoads({"--urdf", urdf, "--input", path("states.csv"), "--output", outPath()});
  EXPECT_EQ(refused.status, 1);
  EXPECT_NE(refused.err.find("link 'arm': inertia is not positive semi-definite"),
            std::string::npos)
      << refused.err;
  EXPECT_FALSE(fs::exists(outPath()));
  const Result r = jointLoads({"--urdf", urdf, "--input", path("states.csv"), "--output", outPath(),
                               "--accept-nonphysical-inertia"});
  ASSERT_EQ(r.status, 0) << r.err;
  for (const char* part :
       {"joint_loads: warning: robot model: link 'arm': inertia is not positive semi-definite",
        "link 'arm': inertia violates the triangle inequality",
        "link 'hand': inertia violates the triangle inequality",
        "full 3-D force and moment are not physical"})
    EXPECT_NE(r.err.find(part), std::string::npos) << part << "\n" << r.err;
  const Table loads = parseTable(readFile(outPath()));
  ASSERT_EQ(loads.rows.size(), 3u);
  const double q[] = {0.0, 0.7, -2.1}, qdd[] = {0.0, -0.4, 3.0}, g = 9.80665;
  for (std::size_t i = 0; i < 3; ++i)  // 1e-12: a few products of O(1) numbers
    EXPECT_NEAR(loads.number(i, "shoulder.effort"), 1.81 * qdd[i] - 2.0 * g * std::cos(q[i]), 1e-12)
        << i;
}

TEST_F(CliTest, PandaWithMimicFingerRoundTripMatchesTheLibrary) {
  // The wrench acts on a finger: a prismatic segment, its link frame rotated in the hand.
  const std::string in = trajectory(
      "states.csv", kPanda, {"--duration", "0.02", "--seed", "3", "--wrench", "panda_leftfinger"});
  const Table input = parseTable(readFile(in));
  // The mimic finger has no columns of its own; its leader has.
  EXPECT_EQ(input.column("panda_finger_joint2.q"), -1);
  EXPECT_GE(input.column("panda_finger_joint1.qdd"), 0);
  const Result r = jointLoads({"--urdf", kPanda, "--input", in, "--output", outPath()});
  ASSERT_EQ(r.status, 0) << r.err;
  std::vector<std::string> joints = pandaArm();
  joints.push_back("panda_finger_joint1");
  joints.push_back("panda_finger_joint2");  // reported: it moves
  expectMatchesLibrary(kPanda, input, parseTable(readFile(outPath())), joints, "panda_leftfinger",
                       jle::WrenchFrame::kChild, Eigen::Vector3d(0, 0, -9.80665));
}

// --kinematics and --friction (docs/outputs.md): after the joints' columns J.q, J.qd,
// J.qdd of every joint (the input's, a mimic finger's from its leader's through
// multiplier and offset), then J.motor_effort = J.effort + damping qd + friction
// tanh(qd / 0.05) from the URDF's <dynamics> (panda: damping 0.003 on the arm's joints).
// Same doubles, same arithmetic: 1e-12 relative as in expectMatchesLibrary.
TEST_F(CliTest, KinematicsAndFrictionColumns) {
  const std::string in = trajectory("states.csv", kPanda, {"--duration", "0.02", "--seed", "5"});
  const Result r = jointLoads({"--urdf", kPanda, "--input", in, "--output", outPath(),
                               "--kinematics", "--friction", "--velocity-scale", "0.05"});
  ASSERT_EQ(r.status, 0) << r.err;
  const Table input = parseTable(readFile(in)), out = parseTable(readFile(outPath()));
  const jle::Model<double> model = jle::modelFromUrdfFile(kPanda);
  std::vector<std::string> joints = pandaArm(), header;
  joints.push_back("panda_finger_joint1");
  joints.push_back("panda_finger_joint2");
  header = loadHeader(joints);
  for (const std::string& j : joints)
    for (const char* c : {".q", ".qd", ".qdd"}) header.push_back(j + c);
  for (const std::string& j : joints) header.push_back(j + ".motor_effort");
  ASSERT_EQ(out.header, header);
  ASSERT_EQ(out.rows.size(), input.rows.size());
  const auto near = [](double a, double b) {
    return std::abs(a - b) <= 1e-12 * std::max(1.0, std::abs(b));
  };
  for (std::size_t row = 0; row < out.rows.size(); ++row)
    for (const std::string& j : joints) {
      const int s = model.segmentOfJoint(j);
      const std::string leader = model.coordinate_names[model.coordinate[s]];
      const double k = model.multiplier[s], qd = k * input.number(row, leader + ".qd");
      EXPECT_TRUE(
          near(out.number(row, j + ".q"), k * input.number(row, leader + ".q") + model.offset[s]))
          << j << " " << row;
      EXPECT_TRUE(near(out.number(row, j + ".qd"), qd)) << j << " " << row;
      EXPECT_TRUE(near(out.number(row, j + ".qdd"), k * input.number(row, leader + ".qdd")))
          << j << " " << row;
      const double friction = model.damping[s] * qd + model.friction[s] * std::tanh(qd / 0.05);
      EXPECT_TRUE(
          near(out.number(row, j + ".motor_effort"), out.number(row, j + ".effort") + friction))
          << j << " " << row;
    }
  EXPECT_EQ(model.damping[model.segmentOfJoint("panda_joint1")], 0.003);
  // Only with the csv format; --velocity-scale only with --friction.
  EXPECT_EQ(jointLoads({"--urdf", kPanda, "--input", in, "--kinematics", "--format", "sto"}).status,
            2);
  EXPECT_EQ(jointLoads({"--urdf", kPanda, "--input", in, "--velocity-scale", "0.1"}).status, 2);
}

TEST_F(CliTest, OutputReplacesTheFileALinkNamesAndWritesIntoAFifo) {
  const std::string in = trajectory("states.csv", kPandaChain, {"--duration", "0.003"});
  const Result reference = jointLoads({"--urdf", kPandaChain, "--input", in});
  ASSERT_EQ(reference.status, 0) << reference.err;

  writeFile(outDir() + "/real.csv", "previous\n");
  fs::create_symlink("real.csv", outDir() + "/link.csv");
  const Result r =
      jointLoads({"--urdf", kPandaChain, "--input", in, "--output", outDir() + "/link.csv"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(fs::is_symlink(outDir() + "/link.csv"));
  EXPECT_EQ(readFile(outDir() + "/real.csv"), reference.out);

  // A pipe (like a device) is written in place, never replaced by a file. The test holds
  // the reading end (non-blocking, so nothing waits on anything); the output fits in the
  // pipe's buffer.
  const std::string fifo = outDir() + "/pipe";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0) << std::strerror(errno);
  const int fd = ::open(fifo.c_str(), O_RDONLY | O_NONBLOCK);
  ASSERT_GE(fd, 0) << std::strerror(errno);
  ASSERT_LT(reference.out.size(), 60000u);
  const Result piped = jointLoads({"--urdf", kPandaChain, "--input", in, "--output", fifo});
  std::string received;
  char buffer[4096];
  for (ssize_t n; (n = ::read(fd, buffer, sizeof buffer)) > 0;)
    received.append(buffer, static_cast<std::size_t>(n));
  ::close(fd);
  EXPECT_EQ(piped.status, 0) << piped.err;
  EXPECT_EQ(fs::status(fifo).type(), fs::file_type::fifo);
  EXPECT_EQ(received, reference.out);
}

TEST_F(CliTest, ParentAndWorldFramesAndGravityMatchTheLibrary) {
  const std::string in = trajectory(
      "states.csv", kPanda, {"--duration", "0.01", "--seed", "11", "--wrench", "panda_hand_tcp"});
  const Table input = parseTable(readFile(in));
  std::vector<std::string> joints = pandaArm();
  joints.push_back("panda_finger_joint1");
  joints.push_back("panda_finger_joint2");
  const Eigen::Vector3d tilted(0.5, -1.25, -9.7);
  for (const auto& [name, frame] :
       std::vector<std::pair<std::string, jle::WrenchFrame>>{{"parent", jle::WrenchFrame::kParent},
                                                             {"world", jle::WrenchFrame::kWorld},
                                                             {"child", jle::WrenchFrame::kChild}}) {
    SCOPED_TRACE(name);
    const Result r = jointLoads({"--urdf", kPanda, "--input", in, "--output", outPath(), "--frame",
                                 name, "--gravity=0.5, -1.25 ,-9.7"});
    ASSERT_EQ(r.status, 0) << r.err;
    expectMatchesLibrary(kPanda, input, parseTable(readFile(outPath())), joints, "panda_hand_tcp",
                         frame, tilted);
  }
}

// ------------------------------------------------------------------ input layout

// Positions only (docs/studies/zero_phase.md; the numbers themselves are checked against scipy by
// test_zero_phase_reference): the smoothed inputs that --write-kinematics writes are a
// CSV with the derivatives given, whose loads are the positions-only run's, digit for
// digit; the smoothing options are refused where they do not apply, naming them.
TEST_F(CliTest, PositionsOnlyKinematicsReproduceTheirLoads) {
  const std::string full = trajectory(
      "full.csv", kPandaChain, {"--duration", "0.5", "--rate", "200", "--wrench", "panda_link7"});
  const Table table = parseTable(readFile(full));
  Table positions;
  std::vector<std::size_t> kept;
  for (std::size_t c = 0; c < table.header.size(); ++c) {
    const std::string& name = table.header[c];
    const auto ends = [&](const std::string& end) {
      return name.size() > end.size() &&
             name.compare(name.size() - end.size(), end.size(), end) == 0;
    };
    if (ends(".qd") || ends(".qdd")) continue;
    kept.push_back(c);
    positions.header.push_back(name);
  }
  for (const std::vector<std::string>& row : table.rows) {
    positions.rows.emplace_back();
    for (std::size_t c : kept) positions.rows.back().push_back(row[c]);
  }
  writeFile(path("q.csv"), formatTable(positions));
  const std::string kinematics = outDir() + "/kinematics.csv", again = outDir() + "/again.csv";
  Result r = jointLoads({"--urdf", kPandaChain, "--input", path("q.csv"), "--output", outPath(),
                         "--cutoff", "8", "--write-kinematics", kinematics});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("order 4 per pass, cutoff 8 Hz (given)"), std::string::npos) << r.err;
  r = jointLoads({"--urdf", kPandaChain, "--input", kinematics, "--output", again});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(readFile(again), readFile(outPath()));
  EXPECT_EQ(parseTable(readFile(outPath())).rows.size(), table.rows.size());
  // A position no joint reaches is refused before the smoothing spreads it to its
  // neighbours (every row NaN, before).
  Table absurd = positions;
  absurd.rows[20][static_cast<std::size_t>(absurd.column("panda_joint2.q"))] = "1e300";
  writeFile(path("absurd.csv"), formatTable(absurd));
  r = jointLoads({"--urdf", kPandaChain, "--input", path("absurd.csv")});
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find(path("absurd.csv") + ":22: column 'panda_joint2.q': position of joint "
                                            "'panda_joint2' is 1e+300, beyond its URDF limits"),
            std::string::npos)
      << r.err;

  r = jointLoads({"--urdf", kPandaChain, "--input", full, "--cutoff", "8"});
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("are for a CSV of positions only"), std::string::npos) << r.err;
  r = jointLoads(
      {"--urdf", kPandaChain, "--input", path("q.csv"), "--cutoff", "8", "--cutoff-rule", "gcv"});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("--cutoff-rule is only used with --cutoff auto"), std::string::npos);
  r = jointLoads({"--urdf", kPandaChain, "--input", path("q.csv"), "--filter-order", "9"});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("--filter-order"), std::string::npos) << r.err;
  r = jointLoads({"--urdf", kPandaChain, "--input", path("q.csv"), "--cutoff", "150"});
  EXPECT_EQ(r.status, 1);  // above half the 200 Hz rate
  EXPECT_NE(r.err.find("must be below half the sampling rate"), std::string::npos) << r.err;
}

class CliInputTest : public CliTest {
 protected:
  void SetUp() override {
    CliTest::SetUp();
    in_ = trajectory("states.csv", kPanda,
                     {"--duration", "0.01", "--seed", "5", "--wrench", "panda_hand"});
    const Result r = jointLoads({"--urdf", kPanda, "--input", in_, "--output", outPath()});
    ASSERT_EQ(r.status, 0) << r.err;
    reference_ = readFile(outPath());
    table_ = parseTable(readFile(in_));
  }
  // joint_loads on `text` as input, to standard output.
  Result loadsOf(const std::string& text) const {
    writeFile(path("variant.csv"), text);
    return jointLoads({"--urdf", kPanda, "--input", path("variant.csv")});
  }

  std::string in_, reference_;
  Table table_;
};

TEST_F(CliInputTest, ShuffledColumnsGiveIdenticalOutput) {
  const std::size_t n = table_.header.size();
  ASSERT_EQ(n, 1u + 8 * 3 + 6);  // t, 8 coordinates, one wrench
  // A fixed permutation that moves every column, t and the wrench included.
  std::vector<std::size_t> order(n);
  for (std::size_t i = 0; i < n; ++i) order[i] = (7 * i + 3) % n;  // 7 is prime to 31
  Table shuffled;
  for (std::size_t i : order) shuffled.header.push_back(table_.header[i]);
  for (const auto& row : table_.rows) {
    std::vector<std::string> cells;
    for (std::size_t i : order) cells.push_back(row[i]);
    shuffled.rows.push_back(cells);
  }
  ASSERT_NE(shuffled.header[0], "t");
  const Result r = loadsOf(formatTable(shuffled));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.out, reference_);
}

TEST_F(CliInputTest, BlanksCrlfAndTrailingBlankLineAreAccepted) {
  Table padded = table_;
  for (auto& cell : padded.header) cell = " " + cell + "\t";
  for (auto& row : padded.rows)
    for (auto& cell : row) cell = "\t " + cell + "  ";
  const Result r = loadsOf(formatTable(padded, "\r\n") + "\r\n");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.out, reference_);
}

TEST_F(CliInputTest, MimicColumnsAreAcceptedAndIgnored) {
  Table extra = table_;
  for (const char* s : {".q", ".qd", ".qdd"})
    extra.header.push_back(std::string("panda_finger_joint2") + s);
  for (auto& row : extra.rows)
    for (const char* v : {"0.5", "-3", "100"}) row.push_back(v);  // not what the leader says
  const Result r = loadsOf(formatTable(extra));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.out, reference_);
}

TEST_F(CliInputTest, HeaderOnlyGivesHeaderOnly) {
  const Result r = loadsOf(formatTable(Table{table_.header, {}}));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.out, reference_.substr(0, reference_.find('\n') + 1));
}

// ------------------------------------------------------------------ bad input

struct BadCase {
  std::string name;
  int status;
  std::vector<std::string> message_parts;  // each must appear in the message
};

class CliBadInputTest : public CliTest {
 protected:
  void SetUp() override {
    CliTest::SetUp();
    good_ = parseTable(
        readFile(trajectory("good.csv", kPandaChain,
                            {"--duration", "0.005", "--seed", "2", "--wrench", "panda_hand"})));
    ASSERT_EQ(good_.rows.size(), 6u);  // lines 2 to 7
  }
  // Writes `table` as bad.csv and runs joint_loads on it (expectRefusedArgs).
  void expectRefused(const Table& table, const BadCase& c) {
    writeFile(path("bad.csv"), formatTable(table));
    expectRefusedArgs({"--urdf", kPandaChain, "--input", path("bad.csv"), "--output", outPath()},
                      c);
  }
  // Runs joint_loads and checks the status, that stderr holds one line with every part,
  // and that out/ stays empty.
  void expectRefusedArgs(const std::vector<std::string>& args, const BadCase& c) {
    SCOPED_TRACE(c.name);
    const Result r = jointLoads(args);
    EXPECT_EQ(r.status, c.status) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    for (const std::string& part : c.message_parts)
      EXPECT_NE(r.err.find(part), std::string::npos) << "'" << part << "' not in: " << r.err;
    EXPECT_EQ(outEntries(), std::vector<std::string>{});
  }
  // good_ with cell `column` of data row `row` (line row + 2) replaced.
  Table withCell(std::size_t row, const std::string& column, const std::string& text) const {
    Table t = good_;
    t.rows[row][t.column(column)] = text;
    return t;
  }

  Table good_;
};

TEST_F(CliBadInputTest, BadCellsNameFileLineAndColumn) {
  const std::string file = path("bad.csv");
  // Row 4 is line 6: rows 0 to 3 have been written by then, and must vanish.
  expectRefused(withCell(4, "panda_joint3.qd", ""),
                {"missing cell", 1, {file + ":6: column 'panda_joint3.qd': empty cell"}});
  expectRefused(withCell(4, "panda_joint3.qd", "abc"),
                {"non-numeric", 1, {file + ":6: column 'panda_joint3.qd': 'abc' is not a number"}});
  expectRefused(
      withCell(4, "panda_joint5.q", "1.5x"),
      {"trailing junk", 1, {file + ":6: column 'panda_joint5.q': '1.5x' is not a number"}});
  expectRefused(
      withCell(4, "wrench@panda_hand.my", "nan"),
      {"NaN", 1, {file + ":6: column 'wrench@panda_hand.my': 'nan' is not a finite number"}});
  expectRefused(withCell(5, "t", "-inf"),
                {"inf", 1, {file + ":7: column 't': '-inf' is not a finite number"}});
  expectRefused(withCell(5, "panda_joint1.qdd", "1e400"),
                {"overflow", 1, {file + ":7: column 'panda_joint1.qdd': '1e400' is not a finite"}});
}

// Plausibility at the door (docs/node.md "Never silently wrong"), the rules of the node and
// process_bag: a position no joint reaches (1e300), a velocity of 1e6 rad/s, and in a
// CSV of positions only (differentiated across rows) a one-row glitch of 1 rad (the
// Panda's joint 3 moves 2.175 rad/s: 0.11 rad in a 1 ms row with the margin): the file
// refused, the line, column, joint and value named.
TEST_F(CliBadInputTest, ImplausiblePositionsAndVelocitiesAreRefused) {
  const std::string file = path("bad.csv");
  expectRefused(withCell(4, "panda_joint3.q", "1e300"),
                {"absurd",
                 1,
                 {file + ":6: column 'panda_joint3.q': position of joint 'panda_joint3' is "
                         "1e+300, beyond its URDF limits [-2.8973, 2.8973] by more than "
                         "plausibility/position_margin 1"}});
  Table positions;  // good_ without JOINT.qd, JOINT.qdd
  std::vector<std::size_t> kept;
  for (std::size_t c = 0; c < good_.header.size(); ++c) {
    const std::string& name = good_.header[c];
    if (name.find(".qd") != std::string::npos) continue;  // .qd and .qdd
    kept.push_back(c);
    positions.header.push_back(name);
  }
  for (const std::vector<std::string>& row : good_.rows) {
    positions.rows.emplace_back();
    for (std::size_t c : kept) positions.rows.back().push_back(row[c]);
  }
  std::string& q3 = positions.rows[4][static_cast<std::size_t>(positions.column("panda_joint3.q"))];
  q3 = std::to_string(std::stod(q3) + 1.0);
  expectRefused(positions, {"glitch",
                            1,
                            {file + ":6: column 'panda_joint3.q': position of joint "
                                    "'panda_joint3' moved ",
                             " in 0.001 s, beyond plausibility/velocity_factor 3 times its "
                             "velocity limit 2.175"}});
  expectRefused(withCell(4, "panda_joint3.qd", "1e6"),
                {"velocity",
                 1,
                 {file + ":6: column 'panda_joint3.qd': velocity of joint 'panda_joint3' is "
                         "1000000, beyond"}});
}

// An effort beyond plausibility/effort_factor times the URDF effort limit (a 1e5 N
// wrench on the hand): the loads written, and counted in a warning naming the first.
TEST_F(CliBadInputTest, ImplausibleEffortsAreCountedAndWarned) {
  writeFile(path("heavy.csv"), formatTable(withCell(2, "wrench@panda_hand.fz", "100000")));
  const Result r = jointLoads({"--urdf", kPandaChain, "--input", path("heavy.csv")});
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("joint_loads: warning: 1 rows with an effort beyond plausibility/"
                       "effort_factor 3 times its joint's URDF effort limit (implausible loads; "
                       "the first: line 4, joint 'panda_joint"),
            std::string::npos)
      << r.err;
}

TEST_F(CliBadInputTest, RowsOfTheWrongLengthNameFileLineAndColumn) {
  const std::string file = path("bad.csv");
  ASSERT_EQ(good_.header.size(), 28u);  // t, 7 coordinates, one wrench
  Table shorter = good_;
  shorter.rows[3].pop_back();
  expectRefused(shorter, {"short row",
                          1,
                          {file + ":5: row has 27 cells, the header has 28",
                           "column '" + good_.header.back() + "'"}});
  Table longer = good_;
  longer.rows[3].push_back("1.0");
  expectRefused(longer, {"long row",
                         1,
                         {file + ":5: row has 29 cells, the header has 28", "cell 29",
                          "column '" + good_.header.back() + "'"}});
  Table blank = good_;
  blank.rows.insert(blank.rows.begin() + 2, std::vector<std::string>{""});
  expectRefused(blank, {"blank line inside", 1, {file + ":4: blank line"}});
}

TEST_F(CliBadInputTest, BadHeadersNameTheColumns) {
  const std::string at = path("bad.csv") + ":1: ";
  Table unknown = good_;
  unknown.header.push_back("bogus");
  for (auto& row : unknown.rows) row.push_back("0");
  expectRefused(unknown, {"unknown column", 1, {at + "column 'bogus': unknown column"}});

  Table unknown_joint = good_;
  unknown_joint.header[unknown_joint.column("panda_joint2.qd")] = "panda_jiont2.qd";
  expectRefused(unknown_joint, {"unknown joint",
                                1,
                                {at + "column 'panda_jiont2.qd': unknown joint",
                                 "missing column 'panda_joint2.qd'"}});

  Table fixed_joint = good_;
  fixed_joint.header.push_back("panda_hand_joint.q");  // fixed: no coordinate
  for (auto& row : fixed_joint.rows) row.push_back("0");
  expectRefused(fixed_joint,
                {"fixed joint", 1, {at + "column 'panda_hand_joint.q': unknown joint"}});

  Table missing = good_;
  const int c = missing.column("panda_joint6.qdd");
  missing.header.erase(missing.header.begin() + c);
  for (auto& row : missing.rows) row.erase(row.begin() + c);
  expectRefused(missing, {"missing column", 1, {at + "missing column 'panda_joint6.qdd'"}});

  Table no_t = good_;
  no_t.header[0] = "time";
  expectRefused(no_t,
                {"missing t", 1, {at + "column 'time': unknown column", "missing column 't'"}});

  Table unknown_link = good_;
  for (auto& name : unknown_link.header)
    if (name.rfind("wrench@", 0) == 0) name.replace(0, 17, "wrench@no_such_link");
  expectRefused(unknown_link,
                {"unknown link",
                 1,
                 {at + "columns 'wrench@no_such_link.fx'", "unknown link 'no_such_link'"}});

  Table incomplete = good_;
  const int mz = incomplete.column("wrench@panda_hand.mz");
  incomplete.header.erase(incomplete.header.begin() + mz);
  for (auto& row : incomplete.rows) row.erase(row.begin() + mz);
  expectRefused(incomplete, {"incomplete wrench",
                             1,
                             {at + "wrench@panda_hand: missing column "
                                   "'wrench@panda_hand.mz'"}});

  Table twice = good_;
  twice.header[twice.column("panda_joint4.q")] = "panda_joint3.q";
  expectRefused(twice, {"duplicate column", 1, {at + "column 'panda_joint3.q' appears twice"}});

  writeFile(path("empty.csv"), "");
  expectRefusedArgs({"--urdf", kPandaChain, "--input", path("empty.csv"), "--output", outPath()},
                    {"empty file", 1, {path("empty.csv") + ":1: empty file"}});
}

TEST_F(CliBadInputTest, UnreadableFilesAreNamed) {
  expectRefusedArgs({"--urdf", kPandaChain, "--input", path("absent.csv"), "--output", outPath()},
                    {"missing file", 1, {path("absent.csv") + ": cannot open"}});
  writeFile(path("bad.urdf"), "<robot name=\"r\"><link name=\"a\">\n");
  writeFile(path("good.csv"), formatTable(good_));
  expectRefusedArgs(
      {"--urdf", path("bad.urdf"), "--input", path("good.csv"), "--output", outPath()},
      {"malformed URDF", 1, {path("bad.urdf") + ": malformed XML"}});
  expectRefusedArgs(
      {"--urdf", path("absent.urdf"), "--input", path("good.csv"), "--output", outPath()},
      {"missing URDF", 1, {path("absent.urdf")}});
}

TEST_F(CliBadInputTest, BadOptionsAreUsageErrors) {
  writeFile(path("good.csv"), formatTable(good_));
  const std::vector<std::string> base{"--urdf",         kPandaChain, "--input",
                                      path("good.csv"), "--output",  outPath()};
  const auto with = [&](std::vector<std::string> extra) {
    std::vector<std::string> args = base;
    args.insert(args.end(), extra.begin(), extra.end());
    return args;
  };
  expectRefusedArgs(with({"--frame", "sideways"}), {"bad frame", 2, {"--frame", "'sideways'"}});
  expectRefusedArgs(with({"--gravity", "0,-9.81"}), {"two numbers", 2, {"--gravity", "'0,-9.81'"}});
  expectRefusedArgs(with({"--gravity", "0,0,nan"}), {"nan gravity", 2, {"--gravity", "'0,0,nan'"}});
  expectRefusedArgs(with({"--gravity", "0,0,-9.8,1"}), {"four numbers", 2, {"--gravity"}});
  expectRefusedArgs(with({"--gravity", "0,zero,-9.8"}), {"word", 2, {"--gravity"}});
  expectRefusedArgs(with({"--planar", "maybe"}), {"bad planar", 2, {"--planar", "'maybe'"}});
  expectRefusedArgs(with({"--planar", "auto", "--kinematics"}),
                    {"planar kinematics", 2, {"--planar auto", "--kinematics"}});
  expectRefusedArgs(with({"--planar", "on", "--frame", "world"}),
                    {"planar world frame", 2, {"--planar on", "--frame"}});
  // The --plate frames are z up: gravity off -z with a plate is refused, naming both.
  for (const char* g : {"0,-9.81,0", "0,0,9.81", "0.5,0,-9.8"})
    expectRefusedArgs(with({"--gravity", g, "--plate", "p1=panda_link7,0,0,0"}),
                      {g, 2, {"--gravity", "--plate p1", "along -z"}});
  expectRefusedArgs(with({"--bogus", "1"}), {"unknown option", 2, {"'--bogus'"}});
  expectRefusedArgs(with({"stray"}), {"positional", 2, {"'stray'"}});
  expectRefusedArgs(with({"--frame"}), {"no value", 2, {"--frame"}});
  expectRefusedArgs(with({"--input", path("good.csv")}), {"twice", 2, {"--input"}});
  expectRefusedArgs({"--input", path("good.csv"), "--output", outPath()},
                    {"no urdf", 2, {"--urdf"}});
}

TEST_F(CliBadInputTest, FailureLeavesAnExistingOutputUntouched) {
  writeFile(outPath(), "previous\n");
  writeFile(path("bad.csv"), formatTable(withCell(5, "panda_joint1.q", "x")));
  const Result r =
      jointLoads({"--urdf", kPandaChain, "--input", path("bad.csv"), "--output", outPath()});
  EXPECT_EQ(r.status, 1);
  EXPECT_EQ(readFile(outPath()), "previous\n");
  EXPECT_EQ(outEntries(), std::vector<std::string>{outPath()});  // no temporary left
}

TEST_F(CliTest, HelpDocumentsTheContract) {
  const Result r = jointLoads({"--help"});
  EXPECT_EQ(r.status, 0);
  for (const char* part : {"--urdf", "--input", "--output", "--gravity", "--frame", "JOINT.qdd",
                           "wrench@LINK", "JOINT.effort", "%.17g", "Exit status"})
    EXPECT_NE(r.out.find(part), std::string::npos) << part;
}

// ------------------------------------------------------------------ make_trajectory

TEST_F(CliTest, TrajectoryIsDeterministicAndSeeded) {
  const std::string a =
      readFile(trajectory("a.csv", kPanda, {"--duration", "0.01", "--seed", "9"}));
  const std::string b =
      readFile(trajectory("b.csv", kPanda, {"--duration", "0.01", "--seed", "9"}));
  const std::string c =
      readFile(trajectory("c.csv", kPanda, {"--duration", "0.01", "--seed", "10"}));
  EXPECT_EQ(a, b);
  EXPECT_NE(a.substr(a.find('\n')), c.substr(c.find('\n')));
  EXPECT_EQ(a.substr(0, a.find('\n')), c.substr(0, c.find('\n')));
}

// The documented formula, worked again here from std::mt19937 and the documented draw
// order: what make_trajectory writes is what its --help promises.
TEST_F(CliTest, TrajectoryFollowsTheDocumentedFormula) {
  const Table table = parseTable(readFile(trajectory(
      "s.csv", kPanda,
      {"--duration", "0.5", "--rate", "100", "--seed", "42", "--wrench", "panda_hand"})));
  std::mt19937 gen(42);
  const auto u = [&gen](double lo, double hi) {
    const double a = static_cast<double>(gen() >> 5);
    const double b = static_cast<double>(gen() >> 6);
    return lo + (hi - lo) * ((a * 67108864.0 + b) / 9007199254740992.0);
  };
  const double two_pi = 2.0 * M_PI;
  struct Sine {
    double a, w, p;
  };
  std::vector<std::string> names = pandaArm();
  names.push_back("panda_finger_joint1");  // the mimic finger has no coordinate
  std::vector<std::vector<Sine>> coordinate(names.size());
  for (std::size_t k = 0; k < names.size(); ++k) {
    const int n = u(0, 1) < 0.5 ? 2 : 3;
    const bool prismatic = names[k] == "panda_finger_joint1";
    for (int j = 0; j < n; ++j) {
      Sine s;
      s.a = prismatic ? u(0.002, 0.01) : u(0.05, 0.4);
      s.w = two_pi * u(0.1, 0.8);
      s.p = u(0, two_pi);
      coordinate[k].push_back(s);
    }
  }
  std::vector<double> offset(6);
  std::vector<Sine> component(6);
  for (int i = 0; i < 6; ++i) {
    const double scale = i < 3 ? 10.0 : 1.0;
    offset[i] = u(-scale, scale);
    component[i].a = u(0, scale);
    component[i].w = two_pi * u(0.1, 1.0);
    component[i].p = u(0, two_pi);
  }

  std::vector<std::string> header{"t"};
  for (const auto& n : names)
    for (const char* s : {".q", ".qd", ".qdd"}) header.push_back(n + s);
  for (const char* c : {"fx", "fy", "fz", "mx", "my", "mz"})
    header.push_back(std::string("wrench@panda_hand.") + c);
  ASSERT_EQ(table.header, header);
  ASSERT_EQ(table.rows.size(), 51u);
  for (std::size_t r = 0; r < table.rows.size(); ++r) {
    const double t = static_cast<double>(r) / 100.0;
    EXPECT_EQ(table.number(r, "t"), t);
    for (std::size_t k = 0; k < names.size(); ++k) {
      double q = 0, qd = 0, qdd = 0;
      for (const Sine& s : coordinate[k]) {
        q += s.a * std::sin(s.w * t + s.p);
        qd += s.a * s.w * std::cos(s.w * t + s.p);
        qdd -= s.a * s.w * s.w * std::sin(s.w * t + s.p);
      }
      // Same formula and operations; the margin covers a compiler contracting a*b+c
      // differently in the two builds: a few ulps of values up to 30 (|qdd| < 3 A w^2).
      EXPECT_NEAR(table.number(r, names[k] + ".q"), q, 1e-13);
      EXPECT_NEAR(table.number(r, names[k] + ".qd"), qd, 1e-13);
      EXPECT_NEAR(table.number(r, names[k] + ".qdd"), qdd, 1e-12);
    }
    for (int i = 0; i < 6; ++i) {
      const double expected =
          offset[i] + component[i].a * std::sin(component[i].w * t + component[i].p);
      EXPECT_NEAR(table.number(r, header[header.size() - 6 + i]), expected, 1e-13);
    }
  }
}

// qd and qdd are the derivatives of q: central differences agree to O(h^2).
TEST_F(CliTest, TrajectoryDerivativesAreConsistent) {
  const Table table = parseTable(readFile(
      trajectory("s.csv", kPandaChain, {"--duration", "0.2", "--rate", "1000", "--seed", "8"})));
  const double h = 1e-3;
  for (int j = 1; j <= 7; ++j) {
    const std::string n = "panda_joint" + std::to_string(j);
    for (std::size_t r = 1; r + 1 < table.rows.size(); ++r) {
      const double dq = (table.number(r + 1, n + ".q") - table.number(r - 1, n + ".q")) / (2 * h);
      const double dqd =
          (table.number(r + 1, n + ".qd") - table.number(r - 1, n + ".qd")) / (2 * h);
      // Central-difference error h^2/6 |q'''|, |q'''| <= sum A w^3 < 3 * 0.4 * 5.03^3 = 153:
      // 2.6e-5 (and |q''''| < 770 gives 1.3e-4 for qdd); rounding adds 1e-13 / h.
      EXPECT_NEAR(dq, table.number(r, n + ".qd"), 3e-5) << n << " row " << r;
      EXPECT_NEAR(dqd, table.number(r, n + ".qdd"), 1.5e-4) << n << " row " << r;
    }
  }
}

TEST_F(CliTest, TrajectoryRefusesBadOptions) {
  for (const auto& args :
       std::vector<std::vector<std::string>>{{"--urdf", kPanda, "--wrench", "no_such_link"},
                                             {"--urdf", kPanda, "--rate", "0"},
                                             {"--urdf", kPanda, "--duration", "-1"},
                                             {"--urdf", kPanda, "--seed", "-3"},
                                             {"--urdf", kPanda, "--seed", "4294967296"},
                                             {"--urdf", kPanda, "--bogus"},
                                             {"--duration", "1"}}) {
    std::vector<std::string> full = args;
    full.insert(full.end(), {"--output", outPath()});
    const Result r = makeTrajectory(full);
    EXPECT_EQ(r.status, 2) << args.back();
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_EQ(outEntries(), std::vector<std::string>{}) << args.back();
  }
  const Result r = makeTrajectory({"--urdf", path("absent.urdf"), "--output", outPath()});
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find(path("absent.urdf")), std::string::npos) << r.err;
}

// ------------------------------------------------------------------ option values

// The message of the UsageError that `parse` throws ("" if it throws none).
template <typename Parse>
std::string usageError(Parse parse) {
  try {
    parse();
  } catch (const jle::cli::UsageError& e) {
    return e.what();
  }
  return "";
}

TEST(CommandLine, NumbersAndTheirMessages) {
  using jle::cli::Sign;
  using jle::cli::parseNumber;
  EXPECT_EQ(parseNumber("--rate", "2.5"), 2.5);
  EXPECT_EQ(parseNumber("--rate", "-1e-3"), -1e-3);
  for (const char* bad : {"abc", "1.5x", "", " ", "nan", "inf", "1e400", "2,5"})
    EXPECT_EQ(usageError([&] { parseNumber("--rate", bad); }),
              "--rate: '" + std::string(bad) + "' is not a finite number");
  EXPECT_EQ(parseNumber("--noise", "0", Sign::kNonNegative), 0.0);
  EXPECT_EQ(usageError([] { parseNumber("--noise", "-0.1", Sign::kNonNegative); }),
            "--noise: '-0.1' is not a finite number >= 0");
  EXPECT_EQ(parseNumber("--idle", "0.5", Sign::kPositive), 0.5);
  EXPECT_EQ(usageError([] { parseNumber("--idle", "0", Sign::kPositive); }),
            "--idle: '0' is not a finite number > 0");
  EXPECT_EQ(usageError([] { parseNumber("--idle", "x", Sign::kPositive); }),
            "--idle: 'x' is not a finite number > 0");
  EXPECT_EQ(jle::cli::parseNumberIn("--mass", "500", 1.0, 500.0), 500.0);
  EXPECT_EQ(usageError([] { jle::cli::parseNumberIn("--mass", "500.5", 1.0, 500.0); }),
            "--mass: 500.5 is outside 1 .. 500");
  EXPECT_EQ(usageError([] { jle::cli::parseNumberIn("--mass", "heavy", 1.0, 500.0); }),
            "--mass: 'heavy' is not a finite number");
}

TEST(CommandLine, IntegersAndTheirMessages) {
  using jle::cli::parseInteger;
  EXPECT_EQ(parseInteger("--seed", "0", 0, 4294967295ULL), 0u);
  EXPECT_EQ(parseInteger("--seed", "4294967295", 0, 4294967295ULL), 4294967295ULL);
  for (const char* bad :
       {"-3", "+3", " 3", "3 ", "3x", "0x10", "", "4294967296", "18446744073709551616"})
    EXPECT_EQ(usageError([&] { parseInteger("--seed", bad, 0, 4294967295ULL); }),
              "--seed: '" + std::string(bad) + "' is not an integer in 0 .. 4294967295");
  EXPECT_EQ(usageError([] { parseInteger("--strides", "0", 1, 100); }),
            "--strides: '0' is not an integer in 1 .. 100");
  EXPECT_EQ(parseInteger("--strides", "100", 1, 100), 100u);
}

TEST(CommandLine, RequiredValues) {
  const std::map<std::string, std::string> values = {{"--urdf", "a.urdf"}};
  EXPECT_EQ(jle::cli::requiredValue(values, "--urdf", "ROBOT.urdf"), "a.urdf");
  EXPECT_EQ(usageError([&] { jle::cli::requiredValue(values, "--input", "STATES.csv"); }),
            "--input STATES.csv is required");
}

TEST(CommandLine, NumberLists) {
  double v[3] = {0, 0, 0};
  ASSERT_TRUE(jle::cli::parseNumberList("0.5, -1.25 ,-9.7", 3, v));
  EXPECT_EQ(v[0], 0.5);
  EXPECT_EQ(v[1], -1.25);
  EXPECT_EQ(v[2], -9.7);
  for (const char* bad : {"0,-9.81", "0,0,-9.8,1", "0,0,nan", "0,zero,-9.8", "1,,2", "", "1,2,3,"})
    EXPECT_FALSE(jle::cli::parseNumberList(bad, 3, v)) << bad;
}

TEST_F(CliTest, ToolsReportTheSharedMessages) {
  const Result seed = makeTrajectory({"--urdf", kPanda, "--seed", "-3", "--output", outPath()});
  EXPECT_EQ(seed.status, 2);
  EXPECT_EQ(seed.err,
            "make_trajectory: --seed: '-3' is not an integer in 0 .. 4294967295 "
            "(see make_trajectory --help)\n");
  const Result rate = makeTrajectory({"--urdf", kPanda, "--rate", "fast", "--output", outPath()});
  EXPECT_EQ(rate.status, 2);
  EXPECT_EQ(rate.err,
            "make_trajectory: --rate: 'fast' is not a finite number "
            "(see make_trajectory --help)\n");
  const Result mass =
      jointLoads({"--urdf", kPanda, "--input", path("absent.csv"), "--per-kg", "--body-mass", "0"});
  EXPECT_EQ(mass.status, 2);
  EXPECT_EQ(mass.err,
            "joint_loads: --body-mass: '0' is not a finite number > 0 "
            "(see joint_loads --help)\n");
  EXPECT_EQ(outEntries(), std::vector<std::string>{});
}

// ------------------------------------------------- --help and --version of every executable

// The version in package.xml, read here (the tools get it from CMake).
std::string packageVersion() {
  const std::string xml = readFile(JLE_PACKAGE_XML);
  const std::size_t begin = xml.find("<version>"), end = xml.find("</version>");
  EXPECT_NE(begin, std::string::npos);
  return xml.substr(begin + 9, end - begin - 9);
}

// Every executable of the package (the node, src/tools/*, scripts/*) prints
// its usage for --help and its version for --version, exiting 0 without touching ROS:
// the master named here does not exist, and a program that tried to reach it would
// hang until `timeout` kills it (status 124).
TEST_F(CliTest, EveryExecutableHasHelpAndVersion) {
  const std::string version = packageVersion();
  ASSERT_FALSE(version.empty());
  std::vector<std::string> programs;
  for (std::size_t begin = 0, end;; begin = end + 1) {
    end = std::string(JLE_EXECUTABLES).find('|', begin);
    programs.push_back(std::string(JLE_EXECUTABLES).substr(begin, end - begin));
    if (end == std::string::npos) break;
  }
  ASSERT_EQ(programs.size(), 14u);  // the node, 10 tools, rviz_config, joint_labels, plot_efforts
  for (const std::string& program : programs) {
    const std::string name = fs::path(program).filename().string();
    for (const char* option : {"--help", "--version"}) {
      const Result r =
          run("env", {"ROS_MASTER_URI=http://127.0.0.1:9", "timeout", "10", program, option});
      EXPECT_EQ(r.status, 0) << name << " " << option << ": " << r.err;
      EXPECT_EQ(r.err, "") << name << " " << option;
      if (std::string(option) == "--help")
        EXPECT_EQ(r.out.compare(0, 6, "usage:"), 0) << name << ": " << r.out.substr(0, 80);
      else
        EXPECT_EQ(r.out, name + " " + version + "\n");
    }
  }
}

// Every benchmark, study and test program built beside the tools (bench/CMakeLists.txt
// lists those built: JLE_STUDY_PROGRAMS) answers --help with its usage on stdout and exits
// 0 at once: none runs its study, reads its arguments as data or reaches for ROS.
TEST_F(CliTest, EveryStudyProgramAnswersHelp) {
#ifdef JLE_STUDY_PROGRAMS
  std::vector<std::string> programs;
  for (std::size_t begin = 0, end;; begin = end + 1) {
    end = std::string(JLE_STUDY_PROGRAMS).find('|', begin);
    programs.push_back(std::string(JLE_STUDY_PROGRAMS).substr(begin, end - begin));
    if (end == std::string::npos) break;
  }
  EXPECT_GE(programs.size(), 6u);  // accuracy, the benchmarks, the study, soak
  for (const std::string& program : programs) {
    const std::string name = fs::path(program).filename().string();
    const Result r =
        run("env", {"ROS_MASTER_URI=http://127.0.0.1:9", "timeout", "10", program, "--help"});
    EXPECT_EQ(r.status, 0) << name << ": " << r.err;
    EXPECT_EQ(r.err, "") << name;
    EXPECT_EQ(r.out.compare(0, 7 + name.size(), "usage: " + name), 0)
        << name << ": " << r.out.substr(0, 80);
    EXPECT_LT(r.out.size(), 2000u) << name << " did more than print its usage";
  }
#else
  GTEST_SKIP() << "no benchmark or study program is built (CATKIN_ENABLE_TESTING off)";
#endif
}

// -------------------------------------------------------------------------- rviz_config

// rviz_config on the UR5 (its meshes are in a package that is not installed): a Wrench
// display per moving joint on the node's topics, the torque scale 1 / (2 W_j) with W_j the
// weight the joint carries (at least 2 % of the robot's) as the package's C++ reader finds
// it, and a shapes URDF that liburdf reads with the same joints.
TEST_F(CliTest, RvizConfigForTheUr5) {
  const std::string urdf = kData + "/urdf/ur5_robot.urdf";
  const Result r = run(JLE_RVIZ_CONFIG, {"--urdf", urdf, "--output", path("ur5.rviz"), "--node",
                                         "/arm/joint_load_estimator"});
  ASSERT_EQ(r.status, 0) << r.err;
  const jle::Model<double> model = jle::modelFromUrdfFile(urdf);
  const YAML::Node config = YAML::LoadFile(path("ur5.rviz"));
  const YAML::Node displays = config["Visualization Manager"]["Displays"];
  ASSERT_TRUE(displays.IsSequence());
  // carried[i]: the mass of segment i and of every segment after it [kg] (parent[i] < i).
  std::vector<double> carried(model.mass.begin(), model.mass.end());
  for (int i = model.nsegments() - 1; i > 0; --i) carried[model.parent[i]] += carried[i];
  std::vector<int> moving;
  for (int i = 1; i < model.nsegments(); ++i)
    if (model.joint_type[i] != jle::JointType::kFixed) moving.push_back(i);
  ASSERT_EQ(moving.size(), 6u);
  const YAML::Node wrenches = displays[2]["Displays"];
  ASSERT_EQ(wrenches.size(), moving.size());
  for (std::size_t k = 0; k < moving.size(); ++k) {
    const std::string& joint = model.joint_name[moving[k]];
    EXPECT_EQ(wrenches[k]["Class"].as<std::string>(), "rviz/WrenchStamped");
    EXPECT_EQ(wrenches[k]["Topic"].as<std::string>(),
              "/arm/joint_load_estimator/smoothed/wrench/" + joint);
    const double weight =
        std::max(carried[moving[k]], 0.02 * model.totalMass()) * 9.80665;  // W_j [N]
    // 6 significant digits printed.
    EXPECT_NEAR(wrenches[k]["Torque Arrow Scale"].as<double>() * 2.0 * weight, 1.0, 1e-5) << joint;
  }
  EXPECT_EQ(displays[1]["Robot Description"].as<std::string>(), "robot_description_shapes");
  EXPECT_EQ(config["Visualization Manager"]["Global Options"]["Fixed Frame"].as<std::string>(),
            "world");
  urdf::Model original, shapes;
  ASSERT_TRUE(original.initFile(urdf));
  ASSERT_TRUE(shapes.initFile(path("ur5.shapes.urdf")));
  ASSERT_EQ(shapes.joints_.size(), original.joints_.size());
  for (const auto& [name, joint] : original.joints_) {
    ASSERT_EQ(shapes.joints_.count(name), 1u) << name;
    EXPECT_EQ(shapes.joints_.at(name)->type, joint->type) << name;
    EXPECT_EQ(shapes.joints_.at(name)->parent_link_name, joint->parent_link_name) << name;
    const urdf::Vector3& a = shapes.joints_.at(name)->parent_to_joint_origin_transform.position;
    const urdf::Vector3& b = joint->parent_to_joint_origin_transform.position;
    EXPECT_EQ(a.x, b.x) << name;  // the joint elements are copied as they are
    EXPECT_EQ(a.y, b.y) << name;
    EXPECT_EQ(a.z, b.z) << name;
  }
  // Every link with a child joint away from its origin has a cylinder to it.
  for (const auto& [name, link] : shapes.links_) {
    int away = 0, cylinders = 0;
    for (const auto& joint : link->child_joints) {
      const urdf::Vector3& p = joint->parent_to_joint_origin_transform.position;
      away += std::sqrt(p.x * p.x + p.y * p.y + p.z * p.z) > 1e-6;
    }
    for (const auto& visual : link->visual_array)
      cylinders += visual->geometry->type == urdf::Geometry::CYLINDER;
    EXPECT_EQ(cylinders, away) << name;
  }
  const Result bad = run(JLE_RVIZ_CONFIG, {"--urdf", urdf, "--output", path("x.rviz"), "--joints",
                                           "elbow_joint,no_such_joint"});
  EXPECT_EQ(bad.status, 2);
  EXPECT_NE(bad.err.find("'no_such_joint' is not a joint"), std::string::npos) << bad.err;
}

}  // namespace

int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
