// CSV reading and writing for the offline tools (csv.hpp): POSIX getline into one
// reused buffer, cells split and parsed in place with strtod; output formatted with
// 17 significant digits into one reused line.
#include <joint_load_estimator/io/csv.hpp>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <cstring>

namespace jle {
namespace {

bool isBlank(char c) { return c == ' ' || c == '\t'; }

// Calls fn(begin, end) with the trimmed bounds of each comma-separated cell of
// text[0, length); returns the number of cells (a line always has at least one).
template <typename Fn>
int forEachCell(const char* text, std::size_t length, Fn&& fn) {
  int count = 0;
  std::size_t start = 0;
  while (true) {
    std::size_t stop = start;
    while (stop < length && text[stop] != ',') ++stop;
    std::size_t b = start, e = stop;
    while (b < e && isBlank(text[b])) ++b;
    while (e > b && isBlank(text[e - 1])) --e;
    fn(count, b, e);
    ++count;
    if (stop >= length) return count;
    start = stop + 1;
  }
}

// A cell quoted for a message; a runaway cell is shortened.
std::string quoted(std::string_view text) {
  constexpr std::size_t kMax = 40;
  if (text.size() <= kMax) return "'" + std::string(text) + "'";
  return "'" + std::string(text.substr(0, kMax)) + "...'";
}

// 'a', 'b', 'c' (a long list shortened: a whole header of the wrong robot stays readable).
std::string nameList(const std::vector<std::string>& names) {
  constexpr std::size_t kMax = 6;
  std::string out;
  for (std::size_t i = 0; i < names.size() && i < kMax; ++i)
    out += (out.empty() ? "'" : ", '") + names[i] + "'";
  if (names.size() > kMax) out += " and " + std::to_string(names.size() - kMax) + " more";
  return out;
}

// The header's defects, the columns that share a reason listed together, in the order
// of their first column.
class HeaderProblems {
 public:
  void add(const std::string& column, const std::string& reason) {
    for (auto& p : problems_)
      if (!p.first.empty() && p.second == reason) {
        p.first.push_back(column);
        return;
      }
    problems_.push_back({{column}, reason});
  }
  void add(const std::string& problem) { problems_.push_back({{}, problem}); }
  bool empty() const { return problems_.empty(); }
  std::string message() const {
    constexpr std::size_t kMax = 6;
    std::string out;
    for (std::size_t i = 0; i < problems_.size() && i < kMax; ++i) {
      const auto& p = problems_[i];
      if (!out.empty()) out += "; ";
      if (!p.first.empty())
        out += (p.first.size() == 1 ? "column " : "columns ") + nameList(p.first) + ": ";
      out += p.second;
    }
    if (problems_.size() > kMax)
      out += "; and " + std::to_string(problems_.size() - kMax) + " more problems";
    return out;
  }

 private:
  std::vector<std::pair<std::vector<std::string>, std::string>> problems_;
};

std::string errnoText() { return std::strerror(errno); }

constexpr std::array<const char*, 3> kStateSuffixes = {"q", "qd", "qdd"};
const std::string kWrenchPrefix = "wrench@";
const std::string kBasePrefix = "base.";
const std::string kPlatePrefix = "plate@";
constexpr std::array<const char*, 7> kBasePose = {"x", "y", "z", "qx", "qy", "qz", "qw"};
constexpr std::array<const char*, 6> kBaseTwist = {"vx", "vy", "vz", "wx", "wy", "wz"};
constexpr std::array<const char*, 6> kBaseAcceleration = {"ax", "ay", "az", "alx", "aly", "alz"};

template <std::size_t N>
int indexOf(const std::array<const char*, N>& names, std::string_view name) {
  for (std::size_t i = 0; i < N; ++i)
    if (name == names[i]) return static_cast<int>(i);
  return -1;
}

}  // namespace

// ---------------------------------------------------------------------------- reader

CsvReader::CsvReader(const std::string& path) : path_(path) {
  file_ = std::fopen(path.c_str(), "rb");
  if (!file_) throw CsvError(path_ + ": cannot open: " + errnoText());
  try {
    readHeader();
  } catch (...) {
    // The destructor does not run for an object whose constructor throws.
    std::fclose(file_);
    std::free(buffer_);
    throw;
  }
}

void CsvReader::readHeader() {
  if (!readLine()) throw CsvError(path_ + ":1: empty file, expected a header row");
  // A byte-order mark, as spreadsheet programs write, is not part of the first name.
  if (length_ >= 3 && std::memcmp(buffer_, "\xEF\xBB\xBF", 3) == 0) {
    std::memmove(buffer_, buffer_ + 3, length_ - 3 + 1);
    length_ -= 3;
  }
  line_ = physical_line_;
  forEachCell(buffer_, length_,
              [&](int, std::size_t b, std::size_t e) { header_.emplace_back(buffer_ + b, e - b); });
  if (header_.size() == 1 && header_[0].empty())
    failHeader("blank header row, expected the column names");
  for (int c = 0; c < columns(); ++c) {
    if (header_[c].empty()) failHeader("column " + std::to_string(c + 1) + " has no name");
    for (int d = 0; d < c; ++d)
      if (header_[d] == header_[c])
        failHeader("column '" + header_[c] + "' appears twice (columns " + std::to_string(d + 1) +
                   " and " + std::to_string(c + 1) + ")");
  }
  begin_.assign(header_.size(), 0);
  end_.assign(header_.size(), 0);
}

CsvReader::~CsvReader() {
  if (file_) std::fclose(file_);
  std::free(buffer_);
}

int CsvReader::column(std::string_view name) const {
  for (int c = 0; c < columns(); ++c)
    if (header_[c] == name) return c;
  return -1;
}

bool CsvReader::readLine() {
  errno = 0;
  const ssize_t n = ::getline(&buffer_, &capacity_, file_);
  if (n < 0) {
    if (std::ferror(file_)) throw CsvError(path_ + ": cannot read: " + errnoText());
    return false;
  }
  ++physical_line_;
  std::size_t length = static_cast<std::size_t>(n);
  if (length > 0 && buffer_[length - 1] == '\n') --length;
  if (length > 0 && buffer_[length - 1] == '\r') --length;
  buffer_[length] = '\0';
  length_ = length;
  return true;
}

bool CsvReader::next() {
  const auto blank = [this] {
    return std::all_of(buffer_, buffer_ + length_, [](char c) { return isBlank(c); });
  };
  if (!readLine()) return false;
  if (blank()) {
    // Blank lines end the file; anything after them is a defect.
    const long blank_line = physical_line_;
    while (readLine())
      if (!blank()) {
        line_ = blank_line;
        throw CsvError(path_ + ":" + std::to_string(blank_line) + ": blank line, but line " +
                       std::to_string(physical_line_) + " holds another record");
      }
    return false;
  }
  line_ = physical_line_;
  const std::size_t n = header_.size();
  const int count = forEachCell(buffer_, length_, [this, n](int c, std::size_t b, std::size_t e) {
    if (static_cast<std::size_t>(c) < n) {
      begin_[c] = b;
      end_[c] = e;
    }
  });
  if (count != columns()) {
    const std::string where = path_ + ":" + std::to_string(line_) + ": ";
    if (count < columns())
      throw CsvError(where + "row has " + std::to_string(count) + " cells, the header has " +
                     std::to_string(columns()) + " (no cell for column '" + header_[count] + "')");
    throw CsvError(where + "row has " + std::to_string(count) + " cells, the header has " +
                   std::to_string(columns()) + " (cell " + std::to_string(columns() + 1) +
                   " is beyond the last column '" + header_.back() + "')");
  }
  // Terminate every cell in place so that strtod stops at its end at the latest.
  for (std::size_t c = 0; c < n; ++c) buffer_[end_[c]] = '\0';
  return true;
}

std::string_view CsvReader::cell(int c) const {
  return std::string_view(buffer_ + begin_[c], end_[c] - begin_[c]);
}

double CsvReader::number(int c) const {
  const char* begin = buffer_ + begin_[c];
  const char* end = buffer_ + end_[c];
  if (begin == end) failAt(c, "empty cell");
  char* stop = nullptr;
  const double value = std::strtod(begin, &stop);
  if (stop != end) failAt(c, quoted(cell(c)) + " is not a number");
  if (!std::isfinite(value)) failAt(c, quoted(cell(c)) + " is not a finite number");
  return value;
}

void CsvReader::numbers(double* out) const {
  for (int c = 0; c < columns(); ++c) out[c] = number(c);
}

void CsvReader::failAt(int c, const std::string& what) const {
  throw CsvError(path_ + ":" + std::to_string(line_) + ": column '" + header_[c] + "': " + what);
}

void CsvReader::failHeader(const std::string& what) const { throw CsvError(path_ + ":1: " + what); }

// ---------------------------------------------------------------------------- writer

CsvWriter::CsvWriter(const std::string& path) : path_(path) {
  if (path_.empty()) {
    file_ = stdout;
    return;
  }
  // Through a symbolic link, the file it names is replaced, not the link.
  std::string target = path_;
  struct stat existing;
  if (::lstat(path_.c_str(), &existing) == 0 && S_ISLNK(existing.st_mode))
    if (char* resolved = ::realpath(path_.c_str(), nullptr)) {
      target = resolved;
      std::free(resolved);
    }
  const bool exists = ::stat(target.c_str(), &existing) == 0;
  if (exists && S_ISDIR(existing.st_mode)) throw CsvError(path_ + ": is a directory");
  if (exists && !S_ISREG(existing.st_mode)) {
    // A device or a pipe (/dev/stdout, a FIFO) is written in place: renaming a file
    // onto it would replace the device itself.
    file_ = std::fopen(target.c_str(), "wb");
    if (!file_) throw CsvError(path_ + ": cannot open: " + errnoText());
    return;
  }
  const std::size_t slash = target.rfind('/');
  const std::string directory = slash == std::string::npos ? "." : target.substr(0, slash + 1);
  const std::string base = slash == std::string::npos ? target : target.substr(slash + 1);
  std::string name =
      (slash == std::string::npos ? std::string() : directory) + "." + base + ".tmp.XXXXXX";
  const int fd = ::mkstemp(name.data());
  if (fd < 0)
    throw CsvError(path_ + ": cannot create a temporary file in '" + directory +
                   "': " + errnoText());
  temporary_path_ = name;
  target_ = target;
  // mkstemp creates the file 0600; give it the mode of the file it replaces, or the one
  // a plain fopen would.
  const mode_t mask = ::umask(0);
  ::umask(mask);
  const mode_t mode = exists ? (existing.st_mode & 07777) : (0666 & ~mask);
  if (::fchmod(fd, mode) != 0 || !(file_ = ::fdopen(fd, "wb"))) {
    const std::string reason = errnoText();
    ::close(fd);
    ::unlink(temporary_path_.c_str());
    throw CsvError(path_ + ": cannot open '" + temporary_path_ + "': " + reason);
  }
}

CsvWriter::~CsvWriter() {
  if (file_ && file_ != stdout) std::fclose(file_);
  if (!temporary_path_.empty()) ::unlink(temporary_path_.c_str());
}

void CsvWriter::put() {
  if (std::fwrite(line_.data(), 1, line_.size(), file_) != line_.size())
    throw CsvError((path_.empty() ? std::string("standard output") : path_) +
                   ": cannot write: " + errnoText());
}

void CsvWriter::writeHeader(const std::vector<std::string>& names) {
  line_.clear();
  for (const std::string& name : names) {
    if (name.find_first_of(",\"\r\n") != std::string::npos)
      throw std::invalid_argument("column name '" + name +
                                  "' holds a comma, a quote or a line break");
    if (!line_.empty()) line_ += ',';
    line_ += name;
  }
  line_ += '\n';
  put();
}

void appendNumberRow(std::string& line, const double* values, std::size_t count, char separator) {
  // %.17g is at most 24 characters ("-1.2345678901234567e-308"), plus the separator.
  line.reserve(line.size() + count * 25 + 1);
  char buffer[32];
  for (std::size_t i = 0; i < count; ++i) {
    if (i > 0) line += separator;
#if defined(__cpp_lib_to_chars) && __cpp_lib_to_chars >= 201611L
    // Specified as printf's %.17g in the C locale, and several times faster.
    const std::to_chars_result r =
        std::to_chars(buffer, buffer + sizeof buffer, values[i], std::chars_format::general, 17);
    line.append(buffer, r.ptr);
#else
    const int n = std::snprintf(buffer, sizeof buffer, "%.17g", values[i]);
    line.append(buffer, static_cast<std::size_t>(n));
#endif
  }
  line += '\n';
}

void CsvWriter::writeRow(const double* values, std::size_t count) {
  line_.clear();
  appendNumberRow(line_, values, count, ',');
  put();
}

void CsvWriter::writeText(std::string_view text) {
  line_.assign(text.data(), text.size());
  put();
}

void CsvWriter::commit() {
  const std::string where = path_.empty() ? std::string("standard output") : path_;
  if (std::fflush(file_) != 0 || std::ferror(file_))
    throw CsvError(where + ": cannot write: " + errnoText());
  if (path_.empty()) return;
  // Written in place (a device, a pipe): nothing to sync or rename.
  if (!temporary_path_.empty() && ::fsync(::fileno(file_)) != 0)
    throw CsvError(where + ": cannot sync: " + errnoText());
  std::FILE* file = file_;
  file_ = nullptr;
  if (std::fclose(file) != 0) throw CsvError(where + ": cannot write: " + errnoText());
  if (temporary_path_.empty()) return;
  if (std::rename(temporary_path_.c_str(), target_.c_str()) != 0)
    throw CsvError(where + ": cannot rename '" + temporary_path_ + "' onto it: " + errnoText());
  temporary_path_.clear();
}

// ---------------------------------------------------------------------------- layout

namespace {

// "column 'a'" or "columns 'a', 'b'".
std::string columnList(const std::vector<std::string>& names) {
  return (names.size() == 1 ? "column " : "columns ") + nameList(names);
}

// The names prefix + names[i] of the columns not found (cols[i] < 0).
template <std::size_t N>
std::vector<std::string> absentColumns(const std::array<int, N>& cols, const std::string& prefix,
                                       const std::array<const char*, N>& names) {
  std::vector<std::string> absent;
  for (std::size_t i = 0; i < N; ++i)
    if (cols[i] < 0) absent.push_back(prefix + names[i]);
  return absent;
}

// PREFIX OWNER.COMPONENT (plate@NAME.fx, wrench@LINK.mz): the index of the wrench
// component, -1 if there is none or no owner; the owner into `owner`.
int prefixedComponent(const std::string& name, const std::string& prefix, std::string& owner) {
  const std::size_t dot = name.rfind('.');
  if (dot == std::string::npos || dot <= prefix.size()) return -1;
  owner = name.substr(prefix.size(), dot - prefix.size());
  return indexOf(kWrenchComponents, std::string_view(name).substr(dot + 1));
}

// Maps the columns of one header onto a model (bindStateColumns), collecting its defects.
class StateHeader {
 public:
  StateHeader(const Model<double>& model, const ExtraStateInputs& extra)
      : model_(model), extra_(extra) {
    out_.plates.assign(extra.plates.size(), {-1, -1, -1, -1, -1, -1});
    out_.q.assign(static_cast<std::size_t>(model.nq), -1);
    out_.qd.assign(static_cast<std::size_t>(model.nq), -1);
    out_.qdd.assign(static_cast<std::size_t>(model.nq), -1);
  }

  void bind(int c, const std::string& name) {
    if (name == "t") {
      out_.t = c;
      return;
    }
    if (bindBase(c, name)) return;
    std::string owner;
    if (name.compare(0, kPlatePrefix.size(), kPlatePrefix) == 0) {
      const int component = ownedComponent(name, kPlatePrefix, "NAME", owner);
      if (component >= 0) bindPlate(c, name, owner, component);
    } else if (name.compare(0, kWrenchPrefix.size(), kWrenchPrefix) == 0) {
      const int component = ownedComponent(name, kWrenchPrefix, "LINK", owner);
      if (component >= 0) bindWrench(c, name, owner, component);
    } else {
      bindJoint(c, name);
    }
  }

  // The columns, or a CsvError at line 1 naming every defect.
  StateColumns finish(const CsvReader& reader) {
    checkJoints();
    for (const StateColumns::WrenchColumns& w : out_.wrenches)
      checkComplete(w.column, kWrenchPrefix + w.link);
    if (extra_.floating_base) checkBase();
    for (std::size_t p = 0; p < extra_.plates.size(); ++p)
      checkComplete(out_.plates[p], kPlatePrefix + extra_.plates[p], "plate " + extra_.plates[p]);
    if (!problems_.empty()) reader.failHeader(problems_.message());
    return out_;
  }

 private:
  // base.x ... base.alz (never base.q, base.qd, base.qdd: a joint may be named "base").
  bool bindBase(int c, const std::string& name) {
    const std::string part = name.compare(0, kBasePrefix.size(), kBasePrefix) == 0
                                 ? name.substr(kBasePrefix.size())
                                 : "";
    const int pose = indexOf(kBasePose, part), twist = indexOf(kBaseTwist, part),
              acceleration = indexOf(kBaseAcceleration, part);
    if (pose < 0 && twist < 0 && acceleration < 0) return false;
    if (!extra_.floating_base)
      problems_.add(name, "a floating-base column, but the base is fixed (see --floating-base)");
    else if (pose >= 0)
      out_.base_pose[static_cast<std::size_t>(pose)] = c;
    else if (twist >= 0)
      out_.base_twist[static_cast<std::size_t>(twist)] = c;
    else
      out_.base_acceleration[static_cast<std::size_t>(acceleration)] = c;
    return true;
  }

  // PREFIX OWNER.COMPONENT (plate@NAME.fx, wrench@LINK.mz): the component, or -1 with
  // the problem noted.
  int ownedComponent(const std::string& name, const std::string& prefix, const char* kind,
                     std::string& owner) {
    const int component = prefixedComponent(name, prefix, owner);
    if (component < 0)
      problems_.add(name, "expected " + prefix + kind + ".fx, .fy, .fz, .mx, .my or .mz");
    return component;
  }

  void bindPlate(int c, const std::string& name, const std::string& plate, int component) {
    const auto p = std::find(extra_.plates.begin(), extra_.plates.end(), plate);
    if (p == extra_.plates.end())
      problems_.add(name, "unknown plate '" + plate + "' (no --plate " + plate + "=...)");
    else
      out_.plates[static_cast<std::size_t>(p - extra_.plates.begin())]
                 [static_cast<std::size_t>(component)] = c;
  }

  void bindWrench(int c, const std::string& name, const std::string& link, int component) {
    int frame = -1;
    for (int f = 0; f < static_cast<int>(model_.frames.size()); ++f)
      if (model_.frames[f].name == link) frame = f;
    if (frame < 0) {
      problems_.add(name, "unknown link '" + link + "'");
      return;
    }
    auto w = std::find_if(out_.wrenches.begin(), out_.wrenches.end(),
                          [&](const StateColumns::WrenchColumns& x) { return x.link == link; });
    if (w == out_.wrenches.end()) {
      StateColumns::WrenchColumns added;
      added.link = link;
      added.frame = frame;
      added.column.fill(-1);
      out_.wrenches.push_back(added);
      w = out_.wrenches.end() - 1;
    }
    w->column[static_cast<std::size_t>(component)] = c;
  }

  // JOINT.q, JOINT.qd, JOINT.qdd.
  void bindJoint(int c, const std::string& name) {
    const std::size_t dot = name.rfind('.');
    const int kind = dot == std::string::npos
                         ? -1
                         : indexOf(kStateSuffixes, std::string_view(name).substr(dot + 1));
    if (kind < 0) {
      problems_.add(name,
                    "unknown column (expected t, JOINT.q, JOINT.qd, JOINT.qdd or "
                    "wrench@LINK.fx ... .mz)");
      return;
    }
    const std::string joint = name.substr(0, dot);
    int segment = -1;
    for (int s : model_.moving_segments)
      if (model_.joint_name[s] == joint) segment = s;
    if (segment < 0) {
      problems_.add(name,
                    "unknown joint (no revolute, continuous or prismatic joint of that "
                    "name in the model)");
      return;
    }
    const int k = model_.coordinate[segment];
    if (model_.coordinate_names[k] != joint) return;  // a mimic: follows its leader
    coordinateColumns(kind)[k] = c;
  }

  std::vector<int>& coordinateColumns(int kind) {
    return kind == 0 ? out_.q : kind == 1 ? out_.qd : out_.qdd;
  }

  void checkJoints() {
    std::vector<std::string> missing;
    if (out_.t < 0) missing.push_back("t");
    // Positions only: no JOINT.qdd column at all and JOINT.qd for no joint or for every
    // joint (measured velocities), when the caller allows it.
    const auto none = [](const std::vector<int>& c) {
      return std::all_of(c.begin(), c.end(), [](int i) { return i < 0; });
    };
    const auto every = [](const std::vector<int>& c) {
      return std::all_of(c.begin(), c.end(), [](int i) { return i >= 0; });
    };
    out_.positions_only = extra_.positions_only && model_.nq > 0 && none(out_.qdd) &&
                          (none(out_.qd) || every(out_.qd));
    const int kinds = out_.positions_only ? 1 : 3;
    for (int k = 0; k < model_.nq; ++k)
      for (int kind = 0; kind < kinds; ++kind)
        if (coordinateColumns(kind)[k] < 0)
          missing.push_back(model_.coordinate_names[k] + "." + kStateSuffixes[kind]);
    if (!missing.empty()) problems_.add("missing " + columnList(missing));
  }

  // The six columns of OWNER (wrench@LINK, plate@NAME): all of them (`what` names it).
  void checkComplete(const std::array<int, 6>& cols, const std::string& owner,
                     const std::string& what = "") {
    const std::vector<std::string> absent = absentColumns(cols, owner + ".", kWrenchComponents);
    if (!absent.empty())
      problems_.add((what.empty() ? owner : what) + ": missing " + columnList(absent) +
                    " (all six components are required)");
  }

  void checkBase() {
    const std::vector<std::string> absent = absentColumns(out_.base_pose, kBasePrefix, kBasePose);
    if (!absent.empty())
      problems_.add("floating base: missing " + columnList(absent) +
                    " (the root link's pose is required)");
    // A group given in part counts as absent for the caller; the header is refused anyway.
    checkBaseGroup(out_.base_twist, kBaseTwist, "twist");
    checkBaseGroup(out_.base_acceleration, kBaseAcceleration, "acceleration");
  }

  void checkBaseGroup(const std::array<int, 6>& cols, const std::array<const char*, 6>& names,
                      const char* what) {
    const std::vector<std::string> absent = absentColumns(cols, kBasePrefix, names);
    if (!absent.empty() && absent.size() < cols.size())
      problems_.add(std::string("floating base ") + what + ": missing " + columnList(absent) +
                    " (all six or none)");
  }

  const Model<double>& model_;
  const ExtraStateInputs& extra_;
  StateColumns out_;
  HeaderProblems problems_;
};

}  // namespace

StateColumns bindStateColumns(const Model<double>& model, const CsvReader& reader,
                              const ExtraStateInputs& extra) {
  StateHeader header(model, extra);
  for (int c = 0; c < reader.columns(); ++c) header.bind(c, reader.header()[c]);
  return header.finish(reader);
}

std::vector<std::string> stateColumnNames(const Model<double>& model,
                                          const std::vector<std::string>& wrench_links,
                                          const ExtraStateInputs& extra) {
  std::vector<std::string> names{"t"};
  for (const std::string& joint : model.coordinate_names)
    for (const char* suffix : kStateSuffixes) names.push_back(joint + "." + suffix);
  for (const std::string& link : wrench_links)
    for (const char* component : kWrenchComponents)
      names.push_back(kWrenchPrefix + link + "." + component);
  if (extra.floating_base) {
    for (const char* part : kBasePose) names.push_back(kBasePrefix + part);
    for (const char* part : kBaseTwist) names.push_back(kBasePrefix + part);
    for (const char* part : kBaseAcceleration) names.push_back(kBasePrefix + part);
  }
  for (const std::string& plate : extra.plates)
    for (const char* component : kWrenchComponents)
      names.push_back(kPlatePrefix + plate + "." + component);
  return names;
}

std::vector<std::string> jointLoadColumns(const std::vector<std::string>& joints,
                                          const LoadColumnLayout& layout) {
  std::vector<std::string> names{"t"};
  if (layout.base)
    for (const char* component : kWrenchComponents) names.push_back(kBasePrefix + component);
  for (const std::string& joint : joints) {
    for (const char* component : kWrenchComponents) names.push_back(joint + "." + component);
    names.push_back(joint + ".effort");
    if (layout.per_kg) names.push_back(joint + ".effort_per_kg");
  }
  if (layout.effort_stddev)
    for (const std::string& joint : joints) names.push_back(joint + ".effort_stddev");
  if (layout.kinematics)
    for (const std::string& joint : joints)
      for (const char* c : {".q", ".qd", ".qdd"}) names.push_back(joint + c);
  if (layout.motor_effort)
    for (const std::string& joint : joints) names.push_back(joint + ".motor_effort");
  if (layout.external_effort) {
    for (const std::string& joint : joints) names.push_back(joint + ".external_effort");
    names.push_back("contact");
  }
  for (const std::string& link : layout.contacts)
    for (const char* component : kWrenchComponents)
      names.push_back("external@" + link + "." + component);
  for (const std::string& plate : layout.plates)
    for (const char* column : kPlateOutputs) names.push_back(kPlatePrefix + plate + "." + column);
  if (layout.status) names.push_back("status");
  return names;
}

std::vector<std::string> jointLoadColumns(const Model<double>& model,
                                          const LoadColumnLayout& layout) {
  std::vector<std::string> joints;
  for (int s : model.moving_segments) joints.push_back(model.joint_name[s]);
  return jointLoadColumns(joints, layout);
}

}  // namespace jle
