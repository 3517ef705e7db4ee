// OpenSim storage files (sto.hpp).
#include <joint_load_estimator/sto.hpp>

#include <cerrno>
#include <charconv>
#include <cstring>
#include <stdexcept>

namespace jle {
namespace {

std::string errnoText() { return std::strerror(errno); }

}  // namespace

StoWriter::StoWriter(const std::string& path, std::string name)
    : out_(path), where_(path.empty() ? "standard output" : path), name_(std::move(name)) {
  body_ = std::tmpfile();
  if (!body_) throw CsvError(where_ + ": cannot create a temporary file: " + errnoText());
}

StoWriter::~StoWriter() {
  if (body_) std::fclose(body_);
}

void StoWriter::writeHeader(const std::vector<std::string>& labels) {
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
  static const char* const kComponents[] = {"fx", "fy", "fz", "mx", "my", "mz"};
  static const char* const kBase[] = {"tx_force", "ty_force", "tz_force",
                                      "mx_moment", "my_moment", "mz_moment"};
  std::vector<std::string> out;
  out.reserve(csv_names.size());
  for (const std::string& name : csv_names) {
    if (name == "t") {
      out.push_back("time");
      continue;
    }
    const std::size_t dot = name.rfind('.');
    if (dot == std::string::npos) throw std::invalid_argument("no .sto name for column '" + name + "'");
    const std::string head = name.substr(0, dot), suffix = name.substr(dot + 1);
    if (head == "base") {
      bool found = false;
      for (int i = 0; i < 6; ++i)
        if (suffix == kComponents[i]) {
          out.push_back(model.link_name[0] + "_" + kBase[i]);
          found = true;
        }
      if (!found) throw std::invalid_argument("no .sto name for column '" + name + "'");
      continue;
    }
    if (head.compare(0, 6, "plate@") == 0) {
      const std::string plate = head.substr(6);
      if (suffix == "contact") out.push_back(plate + "_contact");
      else if (suffix == "cop_x") out.push_back(plate + "_ground_force_px");
      else if (suffix == "cop_y") out.push_back(plate + "_ground_force_py");
      else if (suffix == "cop_z") out.push_back(plate + "_ground_force_pz");
      else throw std::invalid_argument("no .sto name for column '" + name + "'");
      continue;
    }
    int segment = -1;  // a moving joint, or a fixed one kept as a segment (process_bag)
    for (int s = 1; s < model.nsegments(); ++s)
      if (model.joint_name[s] == head) segment = s;
    if (segment < 0) throw std::invalid_argument("no .sto name for column '" + name + "'");
    const bool prismatic = model.joint_type[segment] == JointType::kPrismatic;
    const std::string generalized = head + (prismatic ? "_force" : "_moment");
    if (suffix == "effort") {
      out.push_back(generalized);
      continue;
    }
    if (suffix == "effort_per_kg") {
      out.push_back(generalized + "_per_kg");
      continue;
    }
    const std::string in = frame == WrenchFrame::kWorld    ? std::string("ground")
                           : frame == WrenchFrame::kParent ? model.parent_link_name[segment]
                                                           : model.link_name[segment];
    bool found = false;
    for (const char* c : kComponents)
      if (suffix == c) {
        out.push_back(head + "_on_" + model.link_name[segment] + "_in_" + in + "_" + c);
        found = true;
      }
    if (!found) throw std::invalid_argument("no .sto name for column '" + name + "'");
  }
  return out;
}

}  // namespace jle
