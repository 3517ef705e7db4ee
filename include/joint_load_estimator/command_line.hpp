// Command-line options of the package's tools: --key value or --key=value, each known
// key at most once; a defect of the command line is a UsageError (exit status 2).
#pragma once

#include <cstdio>
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

/// The main() of a tool: --help/-h prints `usage`; then run(parse(argc, argv)). A
/// UsageError exits 2 and any other error 1, each with one line on stderr that starts
/// with the tool's name.
template <typename Parse, typename Run>
int runTool(int argc, char** argv, const char* name, const char* usage, Parse parse, Run run) {
  for (int i = 1; i < argc; ++i)
    if (std::string(argv[i]) == "--help" || std::string(argv[i]) == "-h") {
      std::fputs(usage, stdout);
      return 0;
    }
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
