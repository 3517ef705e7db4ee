// OpenSim's storage format (.sto) for the offline tools' joint loads: the header that
// OpenSim's Storage class writes (name, version=1, nRows, nColumns, inDegrees=no,
// endheader), tab-separated labels and rows, the column names that OpenSim's
// InverseDynamics tool and JointReaction analysis use, and OpenSim's ground axes (y up)
// for every world vector (docs/joint_loads.md). ROS-free.
#pragma once

#include <joint_load_estimator/io/csv.hpp>
#include <joint_load_estimator/model/dynamics.hpp>
#include <joint_load_estimator/model/model.hpp>

#include <array>
#include <cstdio>
#include <string>
#include <vector>

namespace jle {

/// The first header line of the files written: the name OpenSim's inverse dynamics
/// tool gives its output (scripts test it to recognise the file).
constexpr const char* kStoName = "Inverse Dynamics Generalized Forces";

/// The .sto columns of a joint_loads / process_bag CSV: the labels (stoColumnNames), and
/// the columns that hold a world vector's x, y, z (base.fx .. fz, base.mx .. mz,
/// plate@P.cop_x .. cop_z, J.fx .. fz and J.mx .. mz in the world frame), which a .sto
/// holds in OpenSim's ground axes (toOpenSimGround).
struct StoLayout {
  std::vector<std::string> labels;
  std::vector<std::array<std::size_t, 3>> world_vectors;  ///< column indices of x, y, z
};

/// OpenSim's ground frame is x forward, y up, z right; the package's world (REP 103) is x
/// forward, y left, z up. A world vector (x, y, z) is (x, z, -y) in OpenSim's ground (a
/// turn of -90 degrees about x: forces, moments and points alike).
inline std::array<double, 3> toOpenSimGround(double x, double y, double z) { return {x, z, -y}; }

/// Writes a .sto file of numbers (%.17g, tab-separated), as CsvWriter does a CSV: to a
/// temporary file renamed onto the path by commit(), or to standard output when the
/// path is empty. The header holds the row count, so the rows wait in an anonymous
/// temporary file until commit(); memory does not grow with the number of rows.
class StoWriter {
 public:
  /// Throws CsvError if the output or the temporary file cannot be created.
  explicit StoWriter(const std::string& path, std::string name = kStoName);
  ~StoWriter();
  StoWriter(const StoWriter&) = delete;
  StoWriter& operator=(const StoWriter&) = delete;

  /// The column labels, the first being "time"; throws std::invalid_argument on a label
  /// holding a blank, a tab or a line break.
  void writeHeader(const std::vector<std::string>& labels);
  /// The layout's labels; every row's world vectors are then written in OpenSim's ground
  /// axes (toOpenSimGround).
  void writeHeader(const StoLayout& layout);
  /// One row of `count` numbers (count = the number of labels), world vectors in the
  /// package's world axes.
  void writeRow(const double* values, std::size_t count);
  /// Writes the header and the rows to the output and renames it onto the path.
  void commit();

 private:
  CsvWriter out_;
  std::string where_;
  std::string name_;
  std::string labels_;
  std::size_t columns_ = 0;
  long rows_ = 0;
  std::FILE* body_ = nullptr;
  std::string line_;
  std::vector<std::array<std::size_t, 3>> world_vectors_;
  std::vector<double> turned_;  // a row with its world vectors turned
};

/// The .sto label of each column of a joint_loads / process_bag CSV (docs/joint_loads.md):
///   t                     -> time
///   J.effort              -> J_moment (revolute) or J_force (prismatic): OpenSim's
///                            generalized force of coordinate J
///   J.effort_per_kg       -> J_moment_per_kg or J_force_per_kg
///   J.fx ... J.mz         -> J_on_CHILD_in_FRAME_fx ... _mz (JointReaction's naming: the
///                            load on the child link at the joint; FRAME = the child link,
///                            the parent link or ground, after `frame`)
///   base.fx, .fy, .fz     -> ROOT_tx_force, ROOT_ty_force, ROOT_tz_force (world frame)
///   base.mx, .my, .mz     -> ROOT_mx_moment, ROOT_my_moment, ROOT_mz_moment (world axes)
///   plate@P.contact       -> P_contact
///   plate@P.cop_x, _y, _z -> P_ground_force_px, _py, _pz (OpenSim's external-load names)
///   status                -> status (the record's LoadsStatus bits, 0: trusted; OpenSim
///                            reads it as one more column)
/// The components of a world vector are OpenSim's ground axes' (y up): a .sto row holds
/// (x, z, -y) of the CSV's (StoLayout, toOpenSimGround); stoLayout says which columns.
/// Throws std::invalid_argument on a name that is none of these.
std::vector<std::string> stoColumnNames(const Model<double>& model,
                                        const std::vector<std::string>& csv_names,
                                        WrenchFrame frame);

/// The labels of the .sto of a CSV with `csv_names` (stoColumnNames), and which columns
/// hold world vectors. Throws std::invalid_argument as stoColumnNames, and on a world
/// vector without all three of its columns.
StoLayout stoLayout(const Model<double>& model, const std::vector<std::string>& csv_names,
                    WrenchFrame frame);

}  // namespace jle
