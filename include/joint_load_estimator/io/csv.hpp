// CSV files of numbers for the offline tools: a streaming reader that locates every
// defect as FILE:LINE and column, an atomic writer, and the column layout of the
// joint-state and joint-load files (docs/joint_loads.md). ROS-free.
#pragma once

#include <joint_load_estimator/model/model.hpp>

#include <array>
#include <cstddef>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace jle {

/// A defect in a CSV file, or a failure to read or write one. The message is complete
/// and starts with the file: "FILE: ...", "FILE:LINE: ..." or
/// "FILE:LINE: column 'NAME': ...".
class CsvError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Reads a comma-separated file of numbers with a header row, one record per line,
/// without holding it in memory. Cells are trimmed of spaces and tabs; CRLF line ends,
/// a UTF-8 byte-order mark and blank lines at the end of the file are accepted. There is
/// no quoting (a cell holds a name or a number). Once the header is read, reading a
/// record does not allocate.
class CsvReader {
 public:
  /// Opens `path` and reads its header (line 1). Throws CsvError if the file cannot be
  /// read or is empty, or if a column name is empty or repeated.
  explicit CsvReader(const std::string& path);
  ~CsvReader();
  CsvReader(const CsvReader&) = delete;
  CsvReader& operator=(const CsvReader&) = delete;

  /// The path as given, which starts every error message.
  const std::string& path() const { return path_; }
  /// Column names, trimmed, in file order.
  const std::vector<std::string>& header() const { return header_; }
  int columns() const { return static_cast<int>(header_.size()); }
  /// Index of column `name`, or -1 if the header has none.
  int column(std::string_view name) const;

  /// Reads the next record; false at the end of the file. Throws CsvError (with its
  /// line) on a record whose cell count differs from the header's, or on a blank line
  /// followed by more records.
  bool next();
  /// Line number (1-based, the header is line 1) of the current record.
  long line() const { return line_; }
  /// Cell `c` of the current record, trimmed; valid until the next call to next().
  std::string_view cell(int c) const;
  /// Cell `c` of the current record as a finite double (strtod, the whole cell). Throws
  /// CsvError "FILE:LINE: column 'NAME': 'abc' is not a number" (or "empty cell", or
  /// "is not a finite number" for nan, inf and overflow).
  double number(int c) const;
  /// Every cell of the current record as numbers (as number()): out[0 .. columns()).
  void numbers(double* out) const;

  /// Throws CsvError "FILE:LINE: column 'NAME': what" at the current record.
  [[noreturn]] void failAt(int c, const std::string& what) const;
  /// Throws CsvError "FILE:1: what" (a defect of the header).
  [[noreturn]] void failHeader(const std::string& what) const;

 private:
  void readHeader();
  bool readLine();  // the next physical line into buffer_, terminator stripped
  int split();      // cells of buffer_ into begin_/end_ (first columns() of them), count

  std::string path_;
  std::FILE* file_ = nullptr;
  char* buffer_ = nullptr;  // POSIX getline buffer, reused
  std::size_t capacity_ = 0;
  std::size_t length_ = 0;
  long line_ = 0;           // line of the current record
  long physical_line_ = 0;  // lines read so far
  std::vector<std::string> header_;
  std::vector<std::size_t> begin_, end_;  // current record's cells, size columns()
};

/// Writes a CSV of numbers, each printed with 17 significant digits (%.17g, which
/// reads back to the same double). To a file: the rows go to a temporary file in the
/// same directory, renamed onto the path by commit(); if commit() is never reached
/// (an error, an exception) the temporary file is removed and an existing file at the
/// path is untouched (through a symbolic link, the file it names is replaced). A path
/// that names a device or a pipe is written in place. To standard output when the path
/// is empty.
/// Appends `count` numbers to `line`, separated by `separator`, each as printf's %.17g
/// (which reads back as the same double), and a newline. Shared by the CSV and the
/// OpenSim storage writers.
void appendNumberRow(std::string& line, const double* values, std::size_t count, char separator);

class CsvWriter {
 public:
  /// Throws CsvError if the temporary file cannot be created.
  explicit CsvWriter(const std::string& path);
  ~CsvWriter();
  CsvWriter(const CsvWriter&) = delete;
  CsvWriter& operator=(const CsvWriter&) = delete;

  /// The header row; throws std::invalid_argument on a name holding a comma, a quote
  /// or a line break.
  void writeHeader(const std::vector<std::string>& names);
  /// One record of `count` numbers. Does not allocate once the first row is written.
  void writeRow(const double* values, std::size_t count);
  /// Text written as it is (another format's header or body, e.g. sto.hpp).
  void writeText(std::string_view text);
  /// Flushes, syncs and renames the file onto the path (flushes standard output).
  /// Throws CsvError on any write error.
  void commit();

 private:
  void put();  // line_ to the stream; throws on a write error

  std::string path_;            // empty: standard output
  std::string target_;          // the file renamed onto (path_, or what its link names)
  std::string temporary_path_;  // empty when writing in place
  std::FILE* file_ = nullptr;
  std::string line_;
};

/// Where the inputs of one sample are in a joint-state CSV (docs/joint_loads.md):
/// column indices into the record.
struct StateColumns {
  /// An external wrench applied to the robot at the origin of a URDF link, in that
  /// link's frame: columns wrench@LINK.fx, .fy, .fz, .mx, .my, .mz.
  struct WrenchColumns {
    std::string link;
    int frame = -1;  ///< index into Model::frames
    std::array<int, 6> column{};
  };
  int t = -1;
  /// A floating base (ExtraStateInputs::floating_base), -1 where absent: the root link's
  /// pose base.x, .y, .z, .qx, .qy, .qz, .qw; its twist base.vx, .vy, .vz, .wx, .wy, .wz
  /// and its acceleration base.ax, .ay, .az, .alx, .aly, .alz, each all six or none.
  std::array<int, 7> base_pose{-1, -1, -1, -1, -1, -1, -1};
  std::array<int, 6> base_twist{-1, -1, -1, -1, -1, -1};
  std::array<int, 6> base_acceleration{-1, -1, -1, -1, -1, -1};
  bool hasBaseTwist() const { return base_twist[0] >= 0; }
  bool hasBaseAcceleration() const { return base_acceleration[0] >= 0; }
  /// Per plate of ExtraStateInputs::plates: plate@NAME.fx, .fy, .fz, .mx, .my, .mz.
  std::vector<std::array<int, 6>> plates;
  /// Per coordinate (size model.nq, the order of model.coordinate_names): the columns of
  /// JOINT.q, JOINT.qd, JOINT.qdd.
  std::vector<int> q, qd, qdd;
  std::vector<WrenchColumns> wrenches;  ///< in the order of their first column
  /// ExtraStateInputs::positions_only and the header has no JOINT.qdd column, and
  /// JOINT.qd for no joint (qd all -1) or for every joint (measured velocities, the
  /// evidence of the zero-phase cutoff): qdd is all -1 (the caller estimates q's rate and
  /// acceleration).
  bool positions_only = false;
};

/// What a joint-state CSV may hold beyond the joints and the wrenches.
struct ExtraStateInputs {
  /// The base floats: the base.* pose columns are required, twist and acceleration
  /// optional. Without it a base.* column is refused.
  bool floating_base = false;
  /// Force plates: for each NAME, plate@NAME.fx ... .mz are required; a plate@ column
  /// of another name is refused.
  std::vector<std::string> plates;
  /// A header with JOINT.q of every joint, no JOINT.qdd at all and JOINT.qd of no joint
  /// or of every joint is accepted (StateColumns::positions_only); one that has some
  /// JOINT.qdd must have all of JOINT.qd and JOINT.qdd.
  bool positions_only = false;
};

/// Maps a joint-state CSV header onto `model`. Throws CsvError at line 1 naming the
/// culprits: unknown columns (unknown joints, non-moving joints, unknown components),
/// unknown links in wrench@LINK, missing t or JOINT.q/qd/qdd of a joint that has its
/// own coordinate, an incomplete wrench. Columns of mimic joints are accepted and
/// ignored (a mimic follows its leader).
StateColumns bindStateColumns(const Model<double>& model, const CsvReader& reader,
                              const ExtraStateInputs& extra = {});

/// Header of a joint-state CSV, the columns bindStateColumns reads: t, JOINT.q, JOINT.qd,
/// JOINT.qdd per coordinate (the order of model.coordinate_names), the six columns of each
/// wrench link; with extra.floating_base the base's pose, twist and acceleration
/// (base.x ... base.qw, base.vx ... base.wz, base.ax ... base.alz); the six columns of each
/// plate of extra.plates.
std::vector<std::string> stateColumnNames(const Model<double>& model,
                                          const std::vector<std::string>& wrench_links,
                                          const ExtraStateInputs& extra = {});

/// The six components of a wrench column (wrench@LINK.*, plate@NAME.*, JOINT.*, base.*).
inline constexpr std::array<const char*, 6> kWrenchComponents = {"fx", "fy", "fz",
                                                                 "mx", "my", "mz"};
/// The columns of a force plate in a joint-load file: plate@NAME.contact (1 or 0) and the
/// centre of pressure in the world, plate@NAME.cop_x, .cop_y, .cop_z [m].
inline constexpr std::array<const char*, 4> kPlateOutputs = {"contact", "cop_x", "cop_y", "cop_z"};

/// What a joint-load file holds beside t and the seven columns of each joint.
struct LoadColumnLayout {
  /// A floating base: base.fx, .fy, .fz, .mx, .my, .mz (what the world applies to the root
  /// link) after t.
  bool base = false;
  /// JOINT.effort_per_kg after each joint's JOINT.effort.
  bool per_kg = false;
  /// JOINT.effort_stddev of every joint, after the last joint's columns.
  bool effort_stddev = false;
  /// JOINT.q, JOINT.qd, JOINT.qdd of every joint (the coordinates the loads were computed
  /// from), after the effort_stddev columns.
  bool kinematics = false;
  /// JOINT.motor_effort of every joint (friction.hpp), after the kinematics columns.
  bool motor_effort = false;
  /// JOINT.external_effort of every joint, then `contact` (1 in contact, 0 not), after the
  /// motor_effort columns (external_effort.hpp).
  bool external_effort = false;
  /// external@LINK.fx, .fy, .fz, .mx, .my, .mz for each contact LINK (link frame, moment
  /// about its origin), after the external_effort columns.
  std::vector<std::string> contacts;
  /// Force plates: plate@NAME.contact, .cop_x, .cop_y, .cop_z for each NAME.
  std::vector<std::string> plates;
  /// `status` last: the record's LoadsStatus bits (0: trusted; process_bag).
  bool status = false;
};

/// Header of a joint-load file (joint_loads, process_bag; docs/joint_loads.md), in this
/// order: t; base.fx ... base.mz (layout.base); for each of `joints` JOINT.fx, .fy, .fz,
/// .mx, .my, .mz, .effort (and JOINT.effort_per_kg with layout.per_kg); JOINT.effort_stddev
/// for each of `joints` (layout.effort_stddev); JOINT.q, .qd, .qdd for each of `joints`
/// (layout.kinematics); JOINT.motor_effort for each of `joints` (layout.motor_effort);
/// JOINT.external_effort for each of `joints` and contact (layout.external_effort);
/// external@LINK.fx ... .mz per contact link (layout.contacts); the plates' columns
/// (layout.plates).
std::vector<std::string> jointLoadColumns(const std::vector<std::string>& joints,
                                          const LoadColumnLayout& layout = {});

/// jointLoadColumns of the joints of model.moving_segments, in that order.
std::vector<std::string> jointLoadColumns(const Model<double>& model,
                                          const LoadColumnLayout& layout = {});

}  // namespace jle
