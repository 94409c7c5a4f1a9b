#include "checkpoint.hpp"

#include "dynhet/disk.hpp"

#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <vector>

#include <hdf5.h>
#include <hdf5_hl.h>

namespace dynhet {

void write_checkpoint_file(const std::string& path, const Checkpoint& c);
namespace {

constexpr const char* kFormat = "dynhet checkpoint 1";

class File {
public:
  File(hid_t id, const std::string& path) : id_(id), path_(path) {
    if (id < 0) throw std::runtime_error(path + ": cannot open as HDF5");
  }
  ~File() { H5Fclose(id_); }
  File(const File&) = delete;
  File& operator=(const File&) = delete;
  hid_t id() const { return id_; }
  void check(herr_t status, const std::string& what) const {
    if (status < 0) throw std::runtime_error(path_ + ": checkpoint " + what + " failed");
  }

private:
  hid_t id_;
  std::string path_;
};

template <class T> void put(const File& f, const char* name, hid_t type, const std::vector<T>& v) {
  const hsize_t n = v.size();
  f.check(H5LTmake_dataset(f.id(), name, 1, &n, type, v.data()), std::string("writing ") + name);
}

template <class T> void get(const File& f, const char* name, hid_t type, std::vector<T>& v, size_t n) {
  hsize_t dims[1] = {0};
  f.check(H5LTget_dataset_info(f.id(), name, dims, nullptr, nullptr), std::string("reading ") + name);
  if (dims[0] != n) throw std::runtime_error(std::string("checkpoint: ") + name + " has the wrong length");
  v.resize(n);
  f.check(H5LTread_dataset(f.id(), name, type, v.data()), std::string("reading ") + name);
}

void put_attr(const File& f, const char* name, double v) {
  f.check(H5LTset_attribute_double(f.id(), "/", name, &v, 1), name);
}
void put_attr(const File& f, const char* name, int64_t v) {
  long long w = v;
  f.check(H5LTset_attribute_long_long(f.id(), "/", name, &w, 1), name);
}
double get_double(const File& f, const char* name) {
  double v;
  f.check(H5LTget_attribute_double(f.id(), "/", name, &v), name);
  return v;
}
int64_t get_int(const File& f, const char* name) {
  long long v;
  f.check(H5LTget_attribute_long_long(f.id(), "/", name, &v), name);
  return v;
}

} // namespace

void write_checkpoint(const std::string& path, const Checkpoint& c) {
  // A full disk is named as such, before HDF5 half-writes the file (the old
  // checkpoint stays in place: the new one goes to .tmp and is renamed).
  const int64_t need = static_cast<int64_t>(c.state.x.size()) * 64 + static_cast<int64_t>(c.scene_toml.size()) +
                       (int64_t{1} << 20);
  if (const int64_t free = free_bytes(path); free >= 0 && free < need)
    throw std::runtime_error(path + ": no space left on device (ENOSPC) for the checkpoint: it needs about " +
                             std::to_string(need / 1024) + " KiB, " + std::to_string(free / 1024) + " KiB are free");
  try {
    write_checkpoint_file(path, c);
  } catch (const std::exception& e) {
    std::remove((path + ".tmp").c_str());
    if (const int64_t free = free_bytes(path); free >= 0 && free < need)
      throw std::runtime_error(path + ": no space left on device (ENOSPC) while writing the checkpoint (" +
                               std::to_string(free / 1024) + " KiB free)");
    throw;
  }
}

void write_checkpoint_file(const std::string& path, const Checkpoint& c) {
  const std::string tmp = path + ".tmp";
  {
    File f(H5Fcreate(tmp.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT), tmp);
    f.check(H5LTset_attribute_string(f.id(), "/", "format", kFormat), "format");
    f.check(H5LTmake_dataset_string(f.id(), "scene_toml", c.scene_toml.c_str()), "scene");
    const auto& s = c.state;
    put_attr(f, "run_id", c.run_id);
    put_attr(f, "next_frame", int64_t{c.next_frame});
    put_attr(f, "time", s.time);
    put_attr(f, "kick_in", s.kick_in);
    put_attr(f, "collisions", s.counters.collisions);
    put_attr(f, "kicks", s.counters.kicks);
    put_attr(f, "list_rebuilds", s.counters.rebuilds);
    put_attr(f, "stale", s.counters.stale);
    put_attr(f, "tc", s.counters.tc);
    put_attr(f, "kick_redraws", s.counters.kick_redraws);
    put_attr(f, "kick_far", s.counters.kick_far);
    f.check(H5LTset_attribute_string(f.id(), "/", "kick_pairs", c.kick_pairs.c_str()), "kick_pairs");
    put_attr(f, "virial", s.counters.virial);
    put(f, "x", H5T_NATIVE_DOUBLE, s.x);
    put(f, "y", H5T_NATIVE_DOUBLE, s.y);
    put(f, "vx", H5T_NATIVE_DOUBLE, s.vx);
    put(f, "vy", H5T_NATIVE_DOUBLE, s.vy);
    put(f, "last_collision", H5T_NATIVE_DOUBLE, s.last_collision);
    put(f, "image_x", H5T_NATIVE_INT32, s.image_x);
    put(f, "image_y", H5T_NATIVE_INT32, s.image_y);
    put(f, "collision_count", H5T_NATIVE_UINT64, s.collision_count);
    put(f, "rng", H5T_NATIVE_UINT64, std::vector<uint64_t>(s.rng, s.rng + 4));
    f.check(H5Fflush(f.id(), H5F_SCOPE_GLOBAL), "flush");
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0)
    throw std::runtime_error(path + ": cannot move the checkpoint into place");
}

bool is_checkpoint(const std::string& path) {
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  const hid_t f = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  if (f < 0) return false;
  char format[64] = {0};
  hsize_t dims = 0;
  H5T_class_t cls;
  size_t size = 0;
  const bool ok = H5Aexists(f, "format") > 0 && H5LTget_attribute_info(f, "/", "format", &dims, &cls, &size) >= 0 &&
                  size < sizeof format && H5LTget_attribute_string(f, "/", "format", format) >= 0 &&
                  std::string(format) == kFormat;
  H5Fclose(f);
  return ok;
}

void read_h5md_positions(const std::string& path, long n, double box, std::vector<double>& x,
                         std::vector<double>& y) {
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  File f(H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), path);
  const char* name = "particles/all/position/value";
  if (H5LTpath_valid(f.id(), name, 1) <= 0)
    throw std::runtime_error(path + ": no " + name + " (an H5MD file with the particles' positions)");
  int rank = 0;
  f.check(H5LTget_dataset_ndims(f.id(), name, &rank), "reading the positions");
  if (rank < 1 || rank > 3) throw std::runtime_error(path + ": " + name + " has rank " + std::to_string(rank));
  std::vector<hsize_t> dims(rank);
  f.check(H5LTget_dataset_info(f.id(), name, dims.data(), nullptr, nullptr), "reading the positions");
  hsize_t total = 1;
  for (hsize_t d : dims) total *= d;
  const hsize_t frame = 2 * static_cast<hsize_t>(n);
  if (total == 0 || total % frame != 0 || total > (hsize_t{1} << 34))
    throw std::runtime_error(path + ": " + name + " holds " + std::to_string(total) +
                             " numbers, not whole frames of 2 x " + std::to_string(n) + " (the scene's particles)");
  std::vector<double> all(total);
  f.check(H5LTread_dataset_double(f.id(), name, all.data()), "reading the positions");
  x.resize(n), y.resize(n);
  const double* last = all.data() + (total - frame);
  for (long i = 0; i < n; ++i) {
    const double px = last[2 * i], py = last[2 * i + 1];
    if (!std::isfinite(px) || !std::isfinite(py))
      throw std::runtime_error(path + ": particle " + std::to_string(i) + " has a position that is not a number");
    x[i] = px - box * std::floor(px / box), y[i] = py - box * std::floor(py / box);
    if (x[i] >= box) x[i] = 0;
    if (y[i] >= box) y[i] = 0;
  }
  const char* edges = "particles/all/box/edges";
  if (H5LTpath_valid(f.id(), edges, 1) > 0) {
    int er = 0;
    f.check(H5LTget_dataset_ndims(f.id(), edges, &er), "reading the box");
    std::vector<hsize_t> ed(std::max(er, 1));
    f.check(H5LTget_dataset_info(f.id(), edges, ed.data(), nullptr, nullptr), "reading the box");
    hsize_t ne = 1;
    for (int k = 0; k < er; ++k) ne *= ed[k];
    if (ne >= 1 && ne <= 64) {
      std::vector<double> e(ne);
      f.check(H5LTread_dataset_double(f.id(), edges, e.data()), "reading the box");
      for (double v : e)
        if (!(std::fabs(v - box) <= 1e-9 * box))
          throw std::runtime_error(path + ": its box edge " + std::to_string(v) + " is not the scene's box " +
                                   std::to_string(box) + " (N, phi and the radius ratio fix it)");
    }
  }
}

Checkpoint read_checkpoint(const std::string& path) {
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  File f(H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), path);
  char format[64] = {0};
  if (H5LTget_attribute_string(f.id(), "/", "format", format) < 0 || std::string(format) != kFormat)
    throw std::runtime_error(path + ": not a dynhet checkpoint");
  Checkpoint c;
  H5T_class_t cls;
  size_t size = 0;
  hsize_t dims[1];
  f.check(H5LTget_dataset_info(f.id(), "scene_toml", dims, &cls, &size), "reading the scene");
  std::vector<char> text(size + 1, '\0');
  f.check(H5LTread_dataset_string(f.id(), "scene_toml", text.data()), "reading the scene");
  c.scene_toml = text.data();
  c.run_id = get_int(f, "run_id");
  c.next_frame = static_cast<int32_t>(get_int(f, "next_frame"));
  auto& s = c.state;
  s.time = get_double(f, "time");
  s.kick_in = get_double(f, "kick_in");
  s.counters.collisions = get_int(f, "collisions");
  s.counters.kicks = get_int(f, "kicks");
  // Checkpoints from before the neighbour lists counted cell crossings instead.
  s.counters.rebuilds = H5Aexists(f.id(), "list_rebuilds") > 0 ? get_int(f, "list_rebuilds") : 0;
  s.counters.stale = get_int(f, "stale");
  s.counters.tc = get_int(f, "tc");
  // Checkpoints from before neighbour kick pairs drew pairs from the whole system.
  s.counters.kick_redraws = H5Aexists(f.id(), "kick_redraws") > 0 ? get_int(f, "kick_redraws") : 0;
  s.counters.kick_far = H5Aexists(f.id(), "kick_far") > 0 ? get_int(f, "kick_far") : 0;
  if (H5Aexists(f.id(), "kick_pairs") > 0) {
    char rule[32] = {0};
    hsize_t dims = 0;
    H5T_class_t cls;
    size_t size = 0;
    f.check(H5LTget_attribute_info(f.id(), "/", "kick_pairs", &dims, &cls, &size), "kick_pairs");
    if (size >= sizeof rule) throw std::runtime_error(path + ": kick_pairs attribute too long");
    f.check(H5LTget_attribute_string(f.id(), "/", "kick_pairs", rule), "kick_pairs");
    c.kick_pairs = rule;
  }
  s.counters.virial = get_double(f, "virial");
  hsize_t n[1] = {0};
  f.check(H5LTget_dataset_info(f.id(), "x", n, nullptr, nullptr), "reading x");
  get(f, "x", H5T_NATIVE_DOUBLE, s.x, n[0]);
  get(f, "y", H5T_NATIVE_DOUBLE, s.y, n[0]);
  get(f, "vx", H5T_NATIVE_DOUBLE, s.vx, n[0]);
  get(f, "vy", H5T_NATIVE_DOUBLE, s.vy, n[0]);
  get(f, "last_collision", H5T_NATIVE_DOUBLE, s.last_collision, n[0]);
  get(f, "image_x", H5T_NATIVE_INT32, s.image_x, n[0]);
  get(f, "image_y", H5T_NATIVE_INT32, s.image_y, n[0]);
  get(f, "collision_count", H5T_NATIVE_UINT64, s.collision_count, n[0]);
  std::vector<uint64_t> rng;
  get(f, "rng", H5T_NATIVE_UINT64, rng, 4);
  for (int k = 0; k < 4; ++k) s.rng[k] = rng[k];
  // A state with a non-finite number would run on as garbage (a NaN
  // position is never in contact with anything): refused here.
  if (!std::isfinite(s.time) || !std::isfinite(s.counters.virial))
    throw std::runtime_error(path + ": time or virial is not a finite number");
  for (const auto* v : {&s.x, &s.y, &s.vx, &s.vy})
    for (size_t i = 0; i < v->size(); ++i)
      if (!std::isfinite((*v)[i]))
        throw std::runtime_error(path + ": particle " + std::to_string(i) +
                                 " has a non-finite position or velocity; not a usable state");
  return c;
}

} // namespace dynhet
