// Command-line options of the package's tools: --key value or --key=value, each known
// key at most once, and their values as numbers; a defect of the command line is a
// UsageError (exit status 2).
#pragma once

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

namespace jle {
namespace cli {

/// A defect of the command line: the tools exit with status 2.
class UsageError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// The values of the options in argv, keyed by option ("--urdf"); a flag (no value)
/// maps to "1". Throws UsageError naming an unknown option, an unexpected argument, a
/// missing or empty value, or an option given twice.
inline std::map<std::string, std::string> optionValues(int argc, char** argv,
                                                       const std::vector<std::string>& keys,
                                                       const std::vector<std::string>& flags = {}) {
  std::map<std::string, std::string> values;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    const std::size_t eq = arg.find('=');
    const std::string key = arg.compare(0, 2, "--") == 0 ? arg.substr(0, eq) : arg;
    bool known = false, flag = false;
    for (const std::string& k : keys) known = known || k == key;
    for (const std::string& k : flags) flag = flag || k == arg;
    if (!known && !flag)
      throw UsageError(arg.compare(0, 1, "-") == 0 ? "unknown option '" + arg + "'"
                                                   : "unexpected argument '" + arg + "'");
    std::string value = "1";
    if (!flag) {
      if (eq != std::string::npos) {
        value = arg.substr(eq + 1);
      } else {
        if (i + 1 >= argc) throw UsageError(key + " needs a value");
        value = argv[++i];
      }
      if (value.empty()) throw UsageError(key + ": empty value");
    }
    if (!values.emplace(key, value).second) throw UsageError(key + " is given twice");
  }
  return values;
}

/// An option that may be repeated (joint_loads' and csv_to_bag's --plate): its values,
/// as `--key VALUE` or `--key=VALUE`, taken out of argv into `values`, before
/// optionValues (which allows each other option once) reads `rest` (argv[0] first).
inline void takeRepeatedOption(int argc, char** argv, const std::string& key,
                               std::vector<std::string>& values, std::vector<char*>& rest) {
  rest.assign(1, argv[0]);
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == key) {
      if (i + 1 >= argc) throw UsageError(key + " needs a value");
      values.push_back(argv[++i]);
    } else if (arg.compare(0, key.size() + 1, key + "=") == 0) {
      values.push_back(arg.substr(key.size() + 1));
    } else {
      rest.push_back(argv[i]);
    }
  }
}

/// The value of a required option of `values` (optionValues); throws UsageError
/// "KEY WHAT is required" ("--urdf ROBOT.urdf is required") without it.
inline std::string requiredValue(const std::map<std::string, std::string>& values,
                                 const std::string& key, const std::string& what) {
  const auto it = values.find(key);
  if (it == values.end()) throw UsageError(key + " " + what + " is required");
  return it->second;
}

/// The sign a number option must have (parseNumber).
enum class Sign { kAny, kNonNegative, kPositive };

/// `text` (an option's value) as a finite number: strtod must read all of it. Throws
/// UsageError "KEY: 'TEXT' is not a finite number", ending " >= 0" or " > 0" with a
/// `sign` it does not have.
inline double parseNumber(const std::string& key, const std::string& text, Sign sign = Sign::kAny) {
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  const bool ok = end != text.c_str() && *end == '\0' && std::isfinite(v) &&
                  (sign == Sign::kAny || (sign == Sign::kNonNegative ? v >= 0.0 : v > 0.0));
  if (!ok)
    throw UsageError(key + ": '" + text + "' is not a finite number" +
                     (sign == Sign::kAny           ? ""
                      : sign == Sign::kNonNegative ? " >= 0"
                                                   : " > 0"));
  return v;
}

/// parseNumber, within [lo, hi]: beyond, throws UsageError "KEY: TEXT is outside LO .. HI"
/// (the bounds with 4 significant digits).
inline double parseNumberIn(const std::string& key, const std::string& text, double lo, double hi) {
  const double v = parseNumber(key, text);
  if (v < lo || v > hi) {
    char range[64];
    std::snprintf(range, sizeof range, "%.4g .. %.4g", lo, hi);
    throw UsageError(key + ": " + text + " is outside " + range);
  }
  return v;
}

/// `text` as a decimal integer in lo .. hi (digits only: no sign, no blank). Throws
/// UsageError "KEY: 'TEXT' is not an integer in LO .. HI".
inline unsigned long long parseInteger(const std::string& key, const std::string& text,
                                       unsigned long long lo, unsigned long long hi) {
  char* end = nullptr;
  errno = 0;
  const unsigned long long v = std::strtoull(text.c_str(), &end, 10);
  if (text.empty() || text[0] < '0' || text[0] > '9' || *end != '\0' || errno != 0 || v < lo ||
      v > hi)
    throw UsageError(key + ": '" + text + "' is not an integer in " + std::to_string(lo) + " .. " +
                     std::to_string(hi));
  return v;
}

/// "A,B,C..." as exactly `count` finite numbers into out[0 .. count) (blanks after each
/// number accepted, strtod before it). False if `text` is not that.
inline bool parseNumberList(const std::string& text, int count, double* out) {
  const char* s = text.c_str();
  for (int i = 0; i < count; ++i) {
    char* end = nullptr;
    out[i] = std::strtod(s, &end);
    while (end != s && (*end == ' ' || *end == '\t')) ++end;
    const char expected = i + 1 < count ? ',' : '\0';
    if (end == s || *end != expected || !std::isfinite(out[i])) return false;
    s = end + (i + 1 < count ? 1 : 0);
  }
  return true;
}

/// The package's version (package.xml), which CMakeLists.txt defines as JLE_VERSION.
inline const char* version() {
#ifdef JLE_VERSION
  return JLE_VERSION;
#else
  return "(built outside catkin)";
#endif
}

/// --help/-h among the arguments prints `usage`, --version the program's name and
/// version(); true when either was answered (the program then exits 0, doing nothing
/// else). For every main(): the tools through runTool, the benchmarks and studies directly.
inline bool answerHelpOrVersion(int argc, char** argv, const char* name, const char* usage) {
  for (int i = 1; i < argc; ++i)
    if (std::string(argv[i]) == "--help" || std::string(argv[i]) == "-h") {
      std::fputs(usage, stdout);
      return true;
    } else if (std::string(argv[i]) == "--version") {
      std::printf("%s %s\n", name, version());
      return true;
    }
  return false;
}

/// The main() of a tool: --help/-h prints `usage`, --version the tool's name and
/// version(), each exiting 0 before anything else; then run(parse(argc, argv)). A
/// UsageError exits 2 and any other error 1, each with one line on stderr that starts
/// with the tool's name.
template <typename Parse, typename Run>
int runTool(int argc, char** argv, const char* name, const char* usage, Parse parse, Run run) {
  if (answerHelpOrVersion(argc, argv, name, usage)) return 0;
  try {
    run(parse(argc, argv));
  } catch (const UsageError& e) {
    std::fprintf(stderr, "%s: %s (see %s --help)\n", name, e.what(), name);
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s: %s\n", name, e.what());
    return 1;
  }
  return 0;
}

}  // namespace cli
}  // namespace jle
