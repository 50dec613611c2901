#include "run/hdf5_output.hpp"

#include <cstdio>
#include <mutex>
#include <stdexcept>
#include <string>
#include <vector>

#include <hdf5.h>

#include "redres/run/record.hpp"

namespace redres {

namespace {

// Closes an HDF5 handle when it goes out of scope.
class Handle {
 public:
  Handle(hid_t id, herr_t (*close)(hid_t)) : id_(id), close_(close) {}
  Handle(const Handle&) = delete;
  Handle& operator=(const Handle&) = delete;
  ~Handle() {
    if (id_ >= 0) (void)close_(id_);
  }
  [[nodiscard]] hid_t id() const noexcept { return id_; }

 private:
  hid_t id_;
  herr_t (*close_)(hid_t);
};

hid_t check(hid_t id, const char* call) {
  if (id < 0) throw std::runtime_error(std::string("HDF5: ") + call + " failed");
  return id;
}

void check_status(herr_t status, const char* call) {
  if (status < 0) throw std::runtime_error(std::string("HDF5: ") + call + " failed");
}

void write_table(hid_t file, const Hdf5Table& t) {
  const Trajectory& table = *t.table;
  const std::size_t width = table.width(), rows = table.size();
  std::vector<double> kept;  // the rows kept, when not every row is
  const double* data = table.values().data();
  std::size_t count = rows;
  if (t.every > 1) {
    for (std::size_t r = 0; r < rows; ++r) {
      if (recorded_row(r, rows, t.every)) kept.insert(kept.end(), table.row(r), table.row(r) + width);
    }
    data = kept.data();
    count = width == 0 ? 0 : kept.size() / width;
  }
  const hsize_t dims[2] = {count, width};
  const Handle space(check(H5Screate_simple(2, dims, nullptr), "H5Screate_simple"), H5Sclose);
  const Handle set(
      check(H5Dcreate2(file, t.name.c_str(), H5T_IEEE_F64LE, space.id(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT),
            "H5Dcreate2"),
      H5Dclose);
  if (count > 0 && width > 0) {
    check_status(H5Dwrite(set.id(), H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, data), "H5Dwrite");
  }
  const Handle text(check(H5Tcopy(H5T_C_S1), "H5Tcopy"), H5Tclose);
  check_status(H5Tset_size(text.id(), H5T_VARIABLE), "H5Tset_size");
  check_status(H5Tset_cset(text.id(), H5T_CSET_UTF8), "H5Tset_cset");
  const hsize_t n = width;
  const Handle names_space(check(H5Screate_simple(1, &n, nullptr), "H5Screate_simple"), H5Sclose);
  const Handle attr(
      check(H5Acreate2(set.id(), "columns", text.id(), names_space.id(), H5P_DEFAULT, H5P_DEFAULT), "H5Acreate2"),
      H5Aclose);
  std::vector<const char*> names;
  for (const std::string& c : table.columns()) names.push_back(c.c_str());
  check_status(H5Awrite(attr.id(), text.id(), names.data()), "H5Awrite");
}

}  // namespace

void write_hdf5(const std::vector<Hdf5Table>& tables, StagedFile& file) {
  static std::mutex lock;
  const std::lock_guard<std::mutex> guard(lock);
  (void)H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);  // errors are exceptions here, not text on stderr
  if (file.stream() == nullptr) throw std::runtime_error("write_hdf5: the staged file is not open");
  const std::string path = "/proc/self/fd/" + std::to_string(::fileno(file.stream()));
  {
    const Handle h5(check(H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT), "H5Fcreate"), H5Fclose);
    for (const Hdf5Table& t : tables) write_table(h5.id(), t);
    check_status(H5Fflush(h5.id(), H5F_SCOPE_GLOBAL), "H5Fflush");
  }
  file.finish();
}

}  // namespace redres
