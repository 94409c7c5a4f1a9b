#include "dynhet/h5md.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <map>
#include <stdexcept>

#include "h5_util.hpp"
#include "parameters.hpp"

namespace dynhet {

namespace {

// One H5MD time series: a group with step, time and value datasets that
// grow together; n values per record.
struct Series {
  h5::Id step, time, value;
  size_t n = 0;
};

struct ParticleGroup {
  double box_length = 0;
  size_t n = 0;
};

// Keep dirty metadata in memory until a flush: with evictions off the
// cache never writes half an update between flushes, so a killed writer
// leaves the file exactly as of its last flush. The cache may grow past
// its usual size meanwhile; appends flush often, so it stays small.
void keep_metadata_until_flush(hid_t fapl, const std::string &path) {
  H5AC_cache_config_t c{};
  c.version = H5AC__CURR_CACHE_CONFIG_VERSION;
  h5::check_status(H5Pget_mdc_config(fapl, &c), "cannot read cache settings for", path);
  c.evictions_enabled = false;
  c.incr_mode = H5C_incr__off;
  c.flash_incr_mode = H5C_flash_incr__off;
  c.decr_mode = H5C_decr__off;
  h5::check_status(H5Pset_mdc_config(fapl, &c), "cannot set cache settings for", path);
}

// No SWMR and the default (oldest) file format on purpose: a file written
// in SWMR mode and killed keeps its "open for writing" mark, and then
// h5py and h5dump refuse to open it until h5clear is run.
h5::Id create_file(const std::string &path) {
  h5::Id fapl(h5::check(H5Pcreate(H5P_FILE_ACCESS), "cannot make file properties for", path));
  keep_metadata_until_flush(fapl, path);
  return h5::Id(
      h5::check(H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, fapl), "cannot create file", path));
}

std::string default_author() {
  const char *user = std::getenv("USER");
  return user && *user ? user : "dynhet user";
}

// x = p + k L with p in [0, L).
void fold(double x, double box, double &p, int32_t &k) {
  if (!std::isfinite(x)) {
    p = x;
    k = 0;
    return;
  }
  double images = std::floor(x / box);
  p = x - images * box;
  // Rounding can put x a hair outside [0, L) after the division.
  if (p < 0) {
    p += box;
    images -= 1;
  }
  if (p >= box) {
    p -= box;
    images += 1;
  }
  k = static_cast<int32_t>(images);
}

// Records of about 64 KiB per chunk, at most 1024 of them.
hsize_t rows_per_chunk(size_t bytes_per_row) {
  return std::clamp<hsize_t>(65536 / std::max<size_t>(bytes_per_row, 1), 1, 1024);
}

std::pair<std::string, std::string> split_leaf(const std::string &path) {
  const size_t slash = path.rfind('/');
  if (slash == std::string::npos) return {"", path};
  return {path.substr(0, slash), path.substr(slash + 1)};
}

} // namespace

struct H5mdWriter::Impl {
  std::string path;
  h5::Id file;
  bool auto_flush = true;
  std::map<std::string, Series> series; // by path in the file
  std::map<std::string, ParticleGroup> particles;

  hid_t open_file() const {
    if (!file.valid()) throw std::runtime_error("HDF5: '" + path + "' is closed");
    return file;
  }

  void flush() { h5::check_status(H5Fflush(open_file(), H5F_SCOPE_GLOBAL), "cannot flush", path); }
  void changed() {
    if (auto_flush) flush();
  }

  // The series at `group_path`, created on first use with records of
  // `row_shape` (empty: one number per record).
  Series &series_at(const std::string &group_path, hid_t type, std::vector<hsize_t> row_shape,
                    std::vector<hsize_t> chunk) {
    auto it = series.find(group_path);
    if (it != series.end()) return it->second;
    h5::Id group = h5::require_group(open_file(), group_path);
    Series s;
    s.step = h5::create_growing(group, "step", H5T_NATIVE_INT64, {}, {1024});
    s.time = h5::create_growing(group, "time", H5T_NATIVE_DOUBLE, {}, {1024});
    s.value = h5::create_growing(group, "value", type, row_shape, chunk);
    s.n = 1;
    for (hsize_t d : row_shape) s.n *= d;
    return series.emplace(group_path, std::move(s)).first->second;
  }

  void append(Series &s, const std::string &group_path, int64_t step, double time, hid_t mem_type,
              const void *values, size_t n) {
    if (n != s.n)
      throw std::runtime_error("HDF5: '" + group_path + "' records hold " + std::to_string(s.n) +
                               " values, not " + std::to_string(n));
    h5::append_row(s.step, H5T_NATIVE_INT64, &step, group_path + "/step");
    h5::append_row(s.time, H5T_NATIVE_DOUBLE, &time, group_path + "/time");
    h5::append_row(s.value, mem_type, values, group_path + "/value");
  }

  template <class T>
  void append_observable(const std::string &name, int64_t step, double time, const T *v, size_t n) {
    const std::string group_path = "observables/" + name;
    if (n == 0) throw std::runtime_error("HDF5: empty record for '" + group_path + "'");
    std::vector<hsize_t> row, chunk{rows_per_chunk(n * sizeof(T))};
    if (n > 1) {
      row.push_back(n);
      chunk.push_back(n);
    }
    Series &s = series_at(group_path, h5::native_type<T>(), row, chunk);
    append(s, group_path, step, time, h5::native_type<T>(), v, n);
    changed();
  }

  template <class T> void write_fixed(const std::string &name, const std::vector<T> &values) {
    const auto [parent, leaf] = split_leaf("observables/" + name);
    h5::Id group = h5::require_group(open_file(), parent);
    if (H5Lexists(group, leaf.c_str(), H5P_DEFAULT) > 0) H5Ldelete(group, leaf.c_str(), H5P_DEFAULT);
    h5::write_dataset(group, leaf, h5::native_type<T>(), {values.size()}, values.data());
    changed();
  }

  // The object at `object` (a group is created when missing).
  h5::Id object_at(const std::string &object) {
    if (!object.empty() && h5::exists(open_file(), object))
      return h5::Id(h5::check(H5Oopen(file, object.c_str(), H5P_DEFAULT), "cannot open", object));
    return h5::require_group(open_file(), object);
  }

  template <class T> void set_attribute(const std::string &object, const std::string &name, const T &v) {
    h5::Id obj = object_at(object);
    h5::write_attr(obj, name, v);
    changed();
  }
};

H5mdWriter::H5mdWriter(const std::string &path, const std::string &creator_name,
                       const std::string &creator_version, const std::string &author)
    : impl_(std::make_unique<Impl>()) {
  h5::silence_errors();
  impl_->path = path;
  impl_->file = create_file(path);
  h5::Id h5md = h5::require_group(impl_->file, "h5md");
  h5::write_attr(h5md, "version", std::vector<int32_t>{1, 1});
  h5::Id creator = h5::require_group(h5md, "creator");
  h5::write_attr(creator, "name", creator_name);
  h5::write_attr(creator, "version", creator_version);
  h5::Id who = h5::require_group(h5md, "author");
  h5::write_attr(who, "name", author.empty() ? default_author() : author);
  impl_->flush();
}

H5mdWriter::~H5mdWriter() {
  try {
    close();
  } catch (...) {
    // A destructor cannot report; close() explicitly to see errors.
  }
}

H5mdWriter::H5mdWriter(H5mdWriter &&) noexcept = default;
H5mdWriter &H5mdWriter::operator=(H5mdWriter &&) noexcept = default;

const std::string &H5mdWriter::path() const { return impl_->path; }

void H5mdWriter::write_parameters(const std::string &scene_toml) {
  h5::Id params = h5::require_group(impl_->open_file(), "parameters");
  h5::write_string_dataset(params, "scene_toml", scene_toml);
  impl_->changed();
  h5::write_toml_attributes(params, scene_toml);
  impl_->changed();
}

void H5mdWriter::set_particles(const std::string &group, double box_length,
                               const std::vector<int32_t> &species) {
  if (!(box_length > 0) || species.empty())
    throw std::invalid_argument("set_particles: need a box length > 0 and at least one particle");
  h5::Id g = h5::require_group(impl_->open_file(), "particles/" + group);
  h5::Id box = h5::require_group(g, "box");
  h5::write_attr(box, "dimension", int32_t{2});
  h5::write_attr(box, "boundary", std::vector<std::string>{"periodic", "periodic"});
  const double edges[2] = {box_length, box_length};
  h5::write_dataset(box, "edges", H5T_NATIVE_DOUBLE, {2}, edges);
  h5::write_dataset(g, "species", H5T_NATIVE_INT32, {species.size()}, species.data());
  impl_->particles[group] = {box_length, species.size()};
  impl_->changed();
}

void H5mdWriter::set_particles(const std::string &group, double box_length,
                               const std::vector<int8_t> &species) {
  set_particles(group, box_length, std::vector<int32_t>(species.begin(), species.end()));
}

void H5mdWriter::append_frame(int64_t step, double time, const std::vector<double> &unwrapped_xy,
                              const std::string &group) {
  auto it = impl_->particles.find(group);
  if (it == impl_->particles.end())
    throw std::logic_error("append_frame: call set_particles(\"" + group + "\", ...) first");
  const auto [box, n] = it->second;
  if (unwrapped_xy.size() != 2 * n)
    throw std::invalid_argument("append_frame: " + std::to_string(unwrapped_xy.size()) + " coordinates for " +
                                std::to_string(n) + " particles");

  std::vector<double> position(2 * n);
  std::vector<int32_t> image(2 * n);
  for (size_t i = 0; i < 2 * n; ++i) fold(unwrapped_xy[i], box, position[i], image[i]);

  // One frame per chunk, split along particles beyond 64Ki of them.
  const std::vector<hsize_t> row{n, 2}, chunk{1, std::min<hsize_t>(n, 65536), 2};
  const std::string base = "particles/" + group;
  Series &pos = impl_->series_at(base + "/position", H5T_NATIVE_DOUBLE, row, chunk);
  Series &img = impl_->series_at(base + "/image", H5T_NATIVE_INT32, row, chunk);
  impl_->append(pos, base + "/position", step, time, H5T_NATIVE_DOUBLE, position.data(), 2 * n);
  impl_->append(img, base + "/image", step, time, H5T_NATIVE_INT32, image.data(), 2 * n);
  impl_->changed();
}

void H5mdWriter::append_observable(const std::string &path, int64_t step, double time, const double *v,
                                   size_t n) {
  impl_->append_observable(path, step, time, v, n);
}
void H5mdWriter::append_observable(const std::string &path, int64_t step, double time, const int32_t *v,
                                   size_t n) {
  impl_->append_observable(path, step, time, v, n);
}
void H5mdWriter::append_observable(const std::string &path, int64_t step, double time, const int64_t *v,
                                   size_t n) {
  impl_->append_observable(path, step, time, v, n);
}

void H5mdWriter::write_fixed(const std::string &path, const std::vector<double> &values) {
  impl_->write_fixed(path, values);
}
void H5mdWriter::write_fixed(const std::string &path, const std::vector<int32_t> &values) {
  impl_->write_fixed(path, values);
}

void H5mdWriter::set_attribute(const std::string &object, const std::string &name, int32_t v) {
  impl_->set_attribute(object, name, v);
}
void H5mdWriter::set_attribute(const std::string &object, const std::string &name, int64_t v) {
  impl_->set_attribute(object, name, v);
}
void H5mdWriter::set_attribute(const std::string &object, const std::string &name, double v) {
  impl_->set_attribute(object, name, v);
}
void H5mdWriter::set_attribute(const std::string &object, const std::string &name, const std::string &v) {
  impl_->set_attribute(object, name, v);
}

void H5mdWriter::set_attribute(const std::string &object, const std::string &name,
                               const std::vector<double> &v) {
  impl_->set_attribute(object, name, v);
}

void H5mdWriter::flush() { impl_->flush(); }
void H5mdWriter::set_auto_flush(bool on) { impl_->auto_flush = on; }

void H5mdWriter::close() {
  if (!impl_ || !impl_->file.valid()) return;
  impl_->series.clear(); // close the datasets before the file
  impl_->flush();
  h5::check_status(H5Fclose(impl_->file.release()), "cannot close", impl_->path);
}

} // namespace dynhet
