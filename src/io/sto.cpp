// OpenSim storage files (sto.hpp).
#include <joint_load_estimator/io/sto.hpp>

#include <cerrno>
#include <charconv>
#include <cstring>
#include <map>
#include <stdexcept>

namespace jle {
namespace {

std::string errnoText() { return std::strerror(errno); }

[[noreturn]] void noStoName(const std::string& name) {
  throw std::invalid_argument("no .sto name for column '" + name + "'");
}

int componentIndex(const std::string& suffix) {
  for (std::size_t i = 0; i < kWrenchComponents.size(); ++i)
    if (suffix == kWrenchComponents[i]) return static_cast<int>(i);
  return -1;
}

// base.fx ... base.mz: the root's ROOT_tx_force ... ROOT_mz_moment.
std::string baseName(const Model<double>& model, const std::string& name,
                     const std::string& suffix) {
  static const char* const kBase[] = {"tx_force",  "ty_force",  "tz_force",
                                      "mx_moment", "my_moment", "mz_moment"};
  const int i = componentIndex(suffix);
  if (i < 0) noStoName(name);
  return model.link_name[0] + "_" + kBase[i];
}

// plate@P.contact, .cop_x, .cop_y, .cop_z: P_contact, P_ground_force_px, _py, _pz.
std::string plateName(const std::string& name, const std::string& plate,
                      const std::string& suffix) {
  static const char* const kPlate[] = {"_contact", "_ground_force_px", "_ground_force_py",
                                       "_ground_force_pz"};
  for (std::size_t i = 0; i < kPlateOutputs.size(); ++i)
    if (suffix == kPlateOutputs[i]) return plate + kPlate[i];
  noStoName(name);
}

// J.effort, J.effort_per_kg, J.fx ... J.mz of a moving joint, or of a fixed one kept as a
// segment (process_bag).
std::string jointName(const Model<double>& model, const std::string& name, const std::string& joint,
                      const std::string& suffix, WrenchFrame frame) {
  int segment = -1;
  for (int s = 1; s < model.nsegments(); ++s)
    if (model.joint_name[s] == joint) segment = s;
  if (segment < 0) noStoName(name);
  const bool prismatic = model.joint_type[segment] == JointType::kPrismatic;
  const std::string generalized = joint + (prismatic ? "_force" : "_moment");
  if (suffix == "effort") return generalized;
  if (suffix == "effort_per_kg") return generalized + "_per_kg";
  if (componentIndex(suffix) < 0) noStoName(name);
  const std::string in = frame == WrenchFrame::kWorld    ? std::string("ground")
                         : frame == WrenchFrame::kParent ? model.parent_link_name[segment]
                                                         : model.link_name[segment];
  return joint + "_on_" + model.link_name[segment] + "_in_" + in + "_" + suffix;
}

// The world vector a CSV column is a component of (base.f, base.m, plate@P.cop, and with
// the world frame J.f, J.m) and its axis; axis -1: none.
struct VectorPart {
  std::string vector;
  int axis = -1;
};

VectorPart worldVectorPart(const std::string& name, WrenchFrame frame) {
  const std::size_t dot = name.rfind('.');
  if (dot == std::string::npos) return {};
  const std::string head = name.substr(0, dot), suffix = name.substr(dot + 1);
  if (head.compare(0, 6, "plate@") == 0) {
    for (int axis = 0; axis < 3; ++axis)
      if (suffix == kPlateOutputs[static_cast<std::size_t>(axis) + 1]) return {head + ".cop", axis};
    return {};
  }
  const int i = componentIndex(suffix);
  if (i < 0 || (head != "base" && frame != WrenchFrame::kWorld)) return {};
  return {head + (i < 3 ? ".f" : ".m"), i % 3};
}

std::string stoName(const Model<double>& model, const std::string& name, WrenchFrame frame) {
  if (name == "t") return "time";
  if (name == "status") return "status";
  const std::size_t dot = name.rfind('.');
  if (dot == std::string::npos) noStoName(name);
  const std::string head = name.substr(0, dot), suffix = name.substr(dot + 1);
  if (head == "base") return baseName(model, name, suffix);
  if (head.compare(0, 6, "plate@") == 0) return plateName(name, head.substr(6), suffix);
  return jointName(model, name, head, suffix, frame);
}

}  // namespace

StoWriter::StoWriter(const std::string& path, std::string name)
    : out_(path), where_(path.empty() ? "standard output" : path), name_(std::move(name)) {
  body_ = std::tmpfile();
  if (!body_) throw CsvError(where_ + ": cannot create a temporary file: " + errnoText());
}

StoWriter::~StoWriter() {
  if (body_) std::fclose(body_);
}

void StoWriter::writeHeader(const StoLayout& layout) {
  writeHeader(layout.labels);
  for (const std::array<std::size_t, 3>& v : layout.world_vectors)
    for (std::size_t c : v)
      if (c >= columns_) throw std::invalid_argument("a world vector's column is out of range");
  world_vectors_ = layout.world_vectors;
  turned_.resize(columns_);
}

void StoWriter::writeHeader(const std::vector<std::string>& labels) {
  world_vectors_.clear();
  if (labels.empty() || labels[0] != "time")
    throw std::invalid_argument("the first column of a .sto file is 'time'");
  labels_.clear();
  for (const std::string& label : labels) {
    if (label.empty() || label.find_first_of(" \t\r\n") != std::string::npos)
      throw std::invalid_argument("column label '" + label + "' is empty or holds a blank");
    if (!labels_.empty()) labels_ += '\t';
    labels_ += label;
  }
  columns_ = labels.size();
}

void StoWriter::writeRow(const double* values, std::size_t count) {
  if (count != columns_)
    throw std::invalid_argument("a .sto row of " + std::to_string(count) + " numbers, " +
                                std::to_string(columns_) + " columns");
  line_.clear();
  if (!world_vectors_.empty()) {  // in OpenSim's ground axes
    std::copy(values, values + count, turned_.begin());
    for (const std::array<std::size_t, 3>& v : world_vectors_) {
      const std::array<double, 3> g = toOpenSimGround(values[v[0]], values[v[1]], values[v[2]]);
      for (std::size_t k = 0; k < 3; ++k) turned_[v[k]] = g[k];
    }
    values = turned_.data();
  }
  appendNumberRow(line_, values, count, '\t');
  if (std::fwrite(line_.data(), 1, line_.size(), body_) != line_.size())
    throw CsvError(where_ + ": cannot write the temporary file: " + errnoText());
  ++rows_;
}

void StoWriter::commit() {
  // The header of OpenSim's Storage::print (the inverse dynamics tool's output).
  out_.writeText(name_ + "\nversion=1\nnRows=" + std::to_string(rows_) +
                 "\nnColumns=" + std::to_string(columns_) +
                 "\ninDegrees=no\n\n"
                 "Units are S.I. units (second, meters, Newtons, ...)\n"
                 "If the header above contains a line with 'inDegrees', this indicates whether "
                 "rotational values are in degrees (yes) or radians (no).\n\n"
                 "endheader\n" +
                 labels_ + "\n");
  if (std::fflush(body_) != 0 || std::fseek(body_, 0, SEEK_SET) != 0)
    throw CsvError(where_ + ": cannot read back the temporary file: " + errnoText());
  char chunk[1 << 16];
  std::size_t n;
  while ((n = std::fread(chunk, 1, sizeof chunk, body_)) > 0)
    out_.writeText(std::string_view(chunk, n));
  if (std::ferror(body_))
    throw CsvError(where_ + ": cannot read back the temporary file: " + errnoText());
  out_.commit();
}

std::vector<std::string> stoColumnNames(const Model<double>& model,
                                        const std::vector<std::string>& csv_names,
                                        WrenchFrame frame) {
  std::vector<std::string> out;
  out.reserve(csv_names.size());
  for (const std::string& name : csv_names) out.push_back(stoName(model, name, frame));
  return out;
}

StoLayout stoLayout(const Model<double>& model, const std::vector<std::string>& csv_names,
                    WrenchFrame frame) {
  StoLayout layout;
  layout.labels = stoColumnNames(model, csv_names, frame);
  constexpr std::size_t kNone = static_cast<std::size_t>(-1);
  std::map<std::string, std::array<std::size_t, 3>> vectors;
  for (std::size_t c = 0; c < csv_names.size(); ++c) {
    const VectorPart part = worldVectorPart(csv_names[c], frame);
    if (part.axis < 0) continue;
    auto it = vectors.emplace(part.vector, std::array<std::size_t, 3>{kNone, kNone, kNone}).first;
    it->second[static_cast<std::size_t>(part.axis)] = c;
  }
  for (const auto& [name, columns] : vectors) {
    for (std::size_t c : columns)
      if (c == kNone)
        throw std::invalid_argument("the world vector " + name +
                                    " needs its x, y and z columns in a .sto (turned to "
                                    "OpenSim's ground axes)");
    layout.world_vectors.push_back(columns);
  }
  return layout;
}

}  // namespace jle
