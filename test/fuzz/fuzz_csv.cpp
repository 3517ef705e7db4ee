// libFuzzer target: the CSV reader of joint_loads. The fuzz input is the content of a
// joint-state CSV read against the UR5 chain, as `joint_loads` reads it (CsvReader,
// bindStateColumns, numbers, then the dynamics of every record). Any input must be read
// or refused with a jle::CsvError; any other exception, a crash or a sanitizer report
// is a bug. The file is a memfd (the reader takes a path: /proc/self/fd/N).
#include <joint_load_estimator/io/csv.hpp>
#include <joint_load_estimator/model/dynamics.hpp>
#include <joint_load_estimator/model/kinematics.hpp>
#include <joint_load_estimator/model/urdf_reader.hpp>

#include <sys/mman.h>
#include <unistd.h>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#ifndef JLE_FUZZ_DATA
#error "JLE_FUZZ_DATA (the path of test/data) must be defined"
#endif

namespace {

struct Fixture {
  jle::Model<double> model = jle::modelFromUrdfFile(JLE_FUZZ_DATA "/urdf/chains/ur5_chain.urdf");
  jle::Data<double> data{model};
  int fd = memfd_create("fuzz_csv", 0);
  std::string path = "/proc/self/fd/" + std::to_string(fd);
};

Fixture& fixture() {
  static Fixture f;
  if (f.fd < 0) {
    std::perror("memfd_create");
    std::abort();
  }
  return f;
}

void writeAll(int fd, const std::uint8_t* bytes, std::size_t size) {
  if (ftruncate(fd, 0) != 0 || lseek(fd, 0, SEEK_SET) != 0) std::abort();
  while (size > 0) {
    const ssize_t n = write(fd, bytes, size);
    if (n <= 0) std::abort();
    bytes += n;
    size -= static_cast<std::size_t>(n);
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* bytes, std::size_t size) {
  Fixture& f = fixture();
  writeAll(f.fd, bytes, size);
  const jle::Model<double>& model = f.model;
  try {
    jle::CsvReader reader(f.path);
    const jle::StateColumns columns = jle::bindStateColumns(model, reader);
    std::vector<double> cells(static_cast<std::size_t>(reader.columns()));
    jle::VectorX<double> q(model.nq), qd(model.nq), qdd(model.nq);
    long previous_line = reader.line();
    while (reader.next()) {
      if (reader.line() <= previous_line) std::abort();  // lines go forward
      previous_line = reader.line();
      for (int c = 0; c < reader.columns(); ++c) (void)reader.cell(c);
      reader.numbers(cells.data());
      for (double v : cells)
        if (!std::isfinite(v)) std::abort();  // number() promises finite values
      for (int k = 0; k < model.nq; ++k) {
        q[k] = cells.at(static_cast<std::size_t>(columns.q.at(static_cast<std::size_t>(k))));
        qd[k] = cells.at(static_cast<std::size_t>(columns.qd.at(static_cast<std::size_t>(k))));
        qdd[k] = cells.at(static_cast<std::size_t>(columns.qdd.at(static_cast<std::size_t>(k))));
      }
      jle::forwardKinematics(model, f.data, q, qd, qdd, Eigen::Vector3d(0.0, 0.0, -9.80665));
      for (const jle::StateColumns::WrenchColumns& w : columns.wrenches) {
        const auto& c = w.column;
        auto at = [&](int i) {
          return cells.at(static_cast<std::size_t>(c[static_cast<std::size_t>(i)]));
        };
        jle::addExternalWrench(model, f.data, w.frame, Eigen::Vector3d(at(0), at(1), at(2)),
                               Eigen::Vector3d(at(3), at(4), at(5)), jle::WrenchFrame::kLocal);
      }
      jle::inverseDynamics(model, f.data);
    }
  } catch (const jle::CsvError&) {
    // refused with FILE:LINE: the documented outcome
  }
  return 0;
}
