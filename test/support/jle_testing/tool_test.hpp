// The package's command-line tools run as processes by the unit tests: a temporary
// directory per test, a tool's exit status and streams, and CSV tables parsed by the
// tests' own code (so that the tools' reader is not its own judge). Shared by
// test_cli.cpp, test_offline_formats.cpp, test_body.cpp, test_gait_csv.cpp and
// test_process_bag.cpp.
#pragma once

#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace jle_test {

/// `s` quoted for the shell (POSIX sh).
inline std::string quote(const std::string& s) {
  std::string out = "'";
  for (char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

/// The whole file, bytes as they are ("" if it cannot be read).
inline std::string readFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

inline void writeFile(const std::string& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
}

/// A tool run to its end.
struct Result {
  int status = -1;  ///< exit status, -1 if the process did not exit normally
  std::string out, err;
};

/// A table of text cells: a CSV, or the body of a .sto.
struct Table {
  std::vector<std::string> header;
  std::vector<std::vector<std::string>> rows;

  /// Index of column `name`, -1 if there is none.
  int column(const std::string& name) const {
    const auto it = std::find(header.begin(), header.end(), name);
    return it == header.end() ? -1 : static_cast<int>(it - header.begin());
  }
  /// Cell (row, name) as a number; a missing column fails the test and gives NaN.
  double number(std::size_t row, const std::string& name) const {
    const int c = column(name);
    EXPECT_GE(c, 0) << "no column " << name;
    return c < 0 || row >= rows.size() ? NAN : std::strtod(rows[row][c].c_str(), nullptr);
  }
};

/// The cells of one line (a separator at the end makes an empty last cell).
inline std::vector<std::string> splitCells(const std::string& line, char separator = ',') {
  std::vector<std::string> cells;
  std::stringstream s(line);
  std::string cell;
  while (std::getline(s, cell, separator)) cells.push_back(cell);
  if (!line.empty() && line.back() == separator) cells.push_back("");
  return cells;
}

/// A CSV text: the header row, then a row per line (blank lines skipped).
inline Table parseCsv(const std::string& text, char separator = ',') {
  Table t;
  std::stringstream s(text);
  std::string line;
  if (std::getline(s, line)) t.header = splitCells(line, separator);
  while (std::getline(s, line))
    if (!line.empty()) t.rows.push_back(splitCells(line, separator));
  return t;
}

/// A fixture with a temporary directory of its own for each test (removed after it),
/// holding an empty out/ for the tools' outputs.
class ToolTest : public ::testing::Test {
 protected:
  /// `prefix` names the directories: TMPDIR/PREFIX_XXXXXX.
  explicit ToolTest(std::string prefix) : prefix_(std::move(prefix)) {}

  void SetUp() override {
    const char* tmp = std::getenv("TMPDIR");
    std::string pattern = std::string(tmp && *tmp ? tmp : "/tmp") + "/" + prefix_ + "_XXXXXX";
    ASSERT_NE(::mkdtemp(pattern.data()), nullptr) << pattern << ": " << std::strerror(errno);
    dir_ = pattern;
    std::filesystem::create_directory(outDir());
  }
  void TearDown() override {
    std::error_code ignored;
    std::filesystem::remove_all(dir_, ignored);
  }

  std::string path(const std::string& name) const { return dir_ + "/" + name; }
  std::string outDir() const { return dir_ + "/out"; }
  void write(const std::string& name, const std::string& text) const {
    writeFile(path(name), text);
  }

  /// Runs `program` with `args`, its standard output and error captured.
  Result run(const std::string& program, const std::vector<std::string>& args) const {
    std::string command = quote(program);
    for (const std::string& a : args) command += " " + quote(a);
    command += " >" + quote(path("stdout.txt")) + " 2>" + quote(path("stderr.txt"));
    const int raw = std::system(command.c_str());
    Result r;
    r.status = raw != -1 && WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
    r.out = readFile(path("stdout.txt"));
    r.err = readFile(path("stderr.txt"));
    return r;
  }

  std::string prefix_;
  std::string dir_;
};

}  // namespace jle_test
