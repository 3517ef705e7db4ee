// Start-up errors (bad_config.test): the node's executable, started in a namespace whose
// parameters are wrong, must exit non-zero with a message naming the culprit (the
// parameter, the link, the key); started with good ones, it must run. The parameters are
// set by the launch file; the test starts the executable itself (fork and exec) and
// reads its output.
#include <gtest/gtest.h>

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <string>
#include <utility>
#include <vector>

namespace {

struct NodeRun {
  bool exited = false;  ///< by itself (not killed on the time limit)
  int exit_code = -1;   ///< when exited
  std::string output;   ///< stdout and stderr
};

// Starts the node in namespace `ns` and collects its output until it exits, or until
// its output contains `until` (then it is asked to stop with SIGINT, as by Ctrl-C), or
// the time limit (then it is killed).
// `trigger`, when the output first contains its first string, runs its second (a shell
// command) once.
using Trigger = std::pair<std::string, std::string>;
NodeRun runNode(const std::string& ns, const std::string& until = "", double limit = 20.0,
                const Trigger& trigger = {}) {
  NodeRun run;
  int fds[2];
  if (pipe(fds) != 0) {
    ADD_FAILURE() << "pipe failed";
    return run;
  }
  const std::string exe = JLE_NODE, ns_arg = "__ns:=" + ns,
                    name_arg = "__name:=joint_load_estimator";
  const pid_t pid = fork();
  if (pid == 0) {
    // rosconsole's stdout is a pipe here: line-buffer it, so that its messages come as
    // they are logged.
    setenv("ROSCONSOLE_STDOUT_LINE_BUFFERED", "1", 1);
    dup2(fds[1], STDOUT_FILENO);
    dup2(fds[1], STDERR_FILENO);
    close(fds[0]);
    close(fds[1]);
    execl(exe.c_str(), exe.c_str(), ns_arg.c_str(), name_arg.c_str(), static_cast<char*>(nullptr));
    _exit(127);
  }
  close(fds[1]);
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(limit);
  bool signalled = false, eof = false, trigger_done = trigger.first.empty();
  while (!eof) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
        end - std::chrono::steady_clock::now());
    if (left.count() <= 0) break;
    pollfd p{fds[0], POLLIN, 0};
    if (poll(&p, 1, static_cast<int>(left.count())) <= 0) break;
    char buffer[4096];
    const ssize_t n = read(fds[0], buffer, sizeof buffer);
    if (n <= 0) {
      eof = true;
      break;
    }
    run.output.append(buffer, static_cast<std::size_t>(n));
    if (!trigger_done && run.output.find(trigger.first) != std::string::npos) {
      EXPECT_EQ(std::system(trigger.second.c_str()), 0) << trigger.second;
      trigger_done = true;
    }
    if (!signalled && !until.empty() && run.output.find(until) != std::string::npos) {
      kill(pid, SIGINT);
      signalled = true;
    }
  }
  if (!eof) kill(pid, SIGKILL);  // over the time limit: only the process we started
  close(fds[0]);
  int status = 0;
  waitpid(pid, &status, 0);
  run.exited = eof && WIFEXITED(status);
  if (run.exited) run.exit_code = WEXITSTATUS(status);
  return run;
}

// The node refuses the configuration: it exits by itself, non-zero, with a message that
// contains every one of `culprit`.
void expectRefused(const std::string& ns, const std::vector<std::string>& culprit) {
  const NodeRun run = runNode(ns);
  ASSERT_TRUE(run.exited) << "the node in " << ns << " did not exit:\n" << run.output;
  EXPECT_NE(run.exit_code, 0) << run.output;
  for (const std::string& c : culprit)
    EXPECT_NE(run.output.find(c), std::string::npos) << "the message does not name '" << c << "':\n"
                                                     << run.output;
}

// The control: with a good model and the default configuration the node starts (it says
// so), runs until asked to stop, and then exits cleanly. Without it, the tests below
// could pass on a node that cannot start at all.
TEST(BadConfig, GoodConfigurationRuns) {
  const NodeRun run = runNode("/good", "7 segments, 6 coordinates");
  ASSERT_TRUE(run.exited) << run.output;
  EXPECT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find("7 segments, 6 coordinates"), std::string::npos) << run.output;
}

// No robot_description yet (a launch file that sets it later): the node waits, saying
// which parameter, and starts once it is set (here by the test, from the UR5's file).
TEST(BadConfig, MissingRobotDescriptionIsWaitedFor) {
  const std::string set = std::string(
                              "/usr/bin/python3 -c \"import rospy; rospy.set_param("
                              "'/no_description/robot_description', open('") +
                          JLE_TEST_DATA + "/urdf/chains/ur5_chain.urdf').read())\"";
  const NodeRun run = runNode("/no_description", "7 segments, 6 coordinates", 30.0,
                              {"waiting for the parameter", set});
  ASSERT_TRUE(run.exited) << run.output;
  EXPECT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find("waiting for the parameter '/no_description/robot_description'"),
            std::string::npos)
      << run.output;
  EXPECT_NE(run.output.find("7 segments, 6 coordinates"), std::string::npos) << run.output;
}

TEST(BadConfig, RobotDescriptionThatIsNotXml) {
  expectRefused("/not_xml", {"'/not_xml/robot_description'", "malformed XML"});
}

TEST(BadConfig, RobotDescriptionThatIsNeitherANameNorAUrdf) {
  expectRefused("/bad_name", {"'~robot_description' is 'my robot: the arm'",
                              "neither the name of the parameter holding the URDF nor a URDF"});
}

TEST(BadConfig, ModelWithANegativeMass) {
  expectRefused("/bad_model", {"link 'heavy_link'", "negative mass"});
}

TEST(BadConfig, YamlKeyOfTheWrongType) {
  expectRefused("/wrong_type", {"'differentiator/window'", "must be an integer"});
}

TEST(BadConfig, MisspeltYamlKey) {
  expectRefused("/unknown_key", {"unknown parameter 'decimaton'"});
}

// The ko file of each key family (test/config, test_settings.cpp): a value out of range,
// refused by the one validate() with the key named.
TEST(BadConfig, ValueOutOfRangeInEachKeyFamily) {
  expectRefused("/ko_top_level", {"parameter 'diagnostic_period'"});
  expectRefused("/ko_differentiator", {"parameter 'differentiator/order'"});
  expectRefused("/ko_wrenches", {"parameter 'wrenches[1]/sign'"});
  expectRefused("/ko_force_plates", {"parameter 'force_plates[1]/name'"});
  expectRefused("/ko_uncertainty", {"parameter 'uncertainty/position_noise'"});
  expectRefused("/ko_savings", {"parameter 'savings/static_velocity'"});
}

// Hostile parameters (issue 14): refused at start with the key path as the user wrote it.
TEST(BadConfig, EmptyTopicDuplicateJointsAndUnknownLinkNameTheirKeys) {
  expectRefused("/empty_topic", {"parameter 'joint_states_topic' is required"});
  expectRefused("/duplicate_joints", {"parameter 'joints[2]' is 'elbow_joint', as is 'joints[0]'"});
  expectRefused("/unknown_wrench_link",
                {"parameter 'wrenches[1]/link': 'tool9' is not a link of the model"});
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
