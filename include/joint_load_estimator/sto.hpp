// OpenSim's storage format (.sto) for the offline tools' joint loads: the header that
// OpenSim's Storage class writes (name, version=1, nRows, nColumns, inDegrees=no,
// endheader), tab-separated labels and rows, and the column names that OpenSim's
// InverseDynamics tool and JointReaction analysis use (docs/joint_loads.md). ROS-free.
#pragma once

#include <joint_load_estimator/csv.hpp>
#include <joint_load_estimator/dynamics.hpp>
#include <joint_load_estimator/model.hpp>

#include <cstdio>
#include <string>
#include <vector>

namespace jle {

/// The first header line of the files written: the name OpenSim's inverse dynamics
/// tool gives its output (scripts test it to recognise the file).
constexpr const char* kStoName = "Inverse Dynamics Generalized Forces";

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
  /// One row of `count` numbers (count = the number of labels).
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
/// Throws std::invalid_argument on a name that is none of these.
std::vector<std::string> stoColumnNames(const Model<double>& model,
                                        const std::vector<std::string>& csv_names,
                                        WrenchFrame frame);

}  // namespace jle
