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
// grow together, records of `shape`. A series that shares another's clock
// (image shares position's) holds hard links to its step and time and
// writes only its values.
struct Series {
  h5::Id step, time, value;
  H5mdWriter::Shape shape;
  bool owns_clock = true;
  hsize_t records = 0;
  int64_t last_step = 0; // valid when records > 0
};

size_t count_of(const H5mdWriter::Shape &shape) {
  size_t n = 1;
  for (size_t d : shape) n *= d;
  return n;
}

std::string shape_text(const H5mdWriter::Shape &shape) {
  std::string out = "(";
  for (size_t d : shape) out += (out.size() > 1 ? ", " : "") + std::to_string(d);
  return out + ")";
}

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
  // `shape` in chunks of `chunk` (same rank plus one). With `clock_path`,
  // step and time are hard links to that series' (which must exist).
  Series &series_at(const std::string &group_path, hid_t type, const H5mdWriter::Shape &shape,
                    const std::vector<hsize_t> &chunk, const std::string &clock_path = "") {
    auto it = series.find(group_path);
    if (it != series.end()) {
      if (it->second.shape != shape)
        throw std::runtime_error("HDF5: '" + group_path + "' records have shape " +
                                 shape_text(it->second.shape) + ", not " + shape_text(shape));
      return it->second;
    }
    h5::Id group = h5::require_group(open_file(), group_path);
    Series s;
    s.shape = shape;
    if (clock_path.empty()) {
      s.step = h5::create_growing(group, "step", H5T_NATIVE_INT64, {}, {1024});
      s.time = h5::create_growing(group, "time", H5T_NATIVE_DOUBLE, {}, {1024});
    } else {
      for (const char *d : {"step", "time"})
        h5::check_status(
            H5Lcreate_hard(file, (clock_path + "/" + d).c_str(), group, d, H5P_DEFAULT, H5P_DEFAULT),
            "cannot link the clock of", group_path + "/" + d);
      s.owns_clock = false;
    }
    const std::vector<hsize_t> row(shape.begin(), shape.end());
    s.value = h5::create_growing(group, "value", type, row, chunk);
    return series.emplace(group_path, std::move(s)).first->second;
  }

  // Appends, replaces or drops one record (see H5mdWriter::Stamp).
  H5mdWriter::Recorded append(Series &s, const std::string &group_path, const H5mdWriter::Stamp &at,
                              hid_t mem_type, const void *values) {
    using R = H5mdWriter::Recorded;
    if (s.records > 0 && at.step <= s.last_step) {
      if (at.step < s.last_step || !at.replace) return R::dropped;
      const hsize_t last = s.records - 1;
      if (s.owns_clock) h5::write_row(s.time, last, H5T_NATIVE_DOUBLE, &at.time, group_path + "/time");
      h5::write_row(s.value, last, mem_type, values, group_path + "/value");
      return R::replaced;
    }
    if (s.owns_clock) {
      h5::append_row(s.step, H5T_NATIVE_INT64, &at.step, group_path + "/step");
      h5::append_row(s.time, H5T_NATIVE_DOUBLE, &at.time, group_path + "/time");
    }
    h5::append_row(s.value, mem_type, values, group_path + "/value");
    ++s.records;
    s.last_step = at.step;
    return R::appended;
  }

  template <class T>
  H5mdWriter::Recorded append_observable(const std::string &name, const H5mdWriter::Stamp &at, const T *v,
                                         const H5mdWriter::Shape &shape) {
    const std::string group_path = "observables/" + name;
    const size_t n = count_of(shape);
    if (n == 0) throw std::runtime_error("HDF5: empty record for '" + group_path + "'");
    std::vector<hsize_t> chunk{rows_per_chunk(n * sizeof(T))};
    chunk.insert(chunk.end(), shape.begin(), shape.end());
    Series &s = series_at(group_path, h5::native_type<T>(), shape, chunk);
    const H5mdWriter::Recorded r = append(s, group_path, at, h5::native_type<T>(), v);
    if (r != H5mdWriter::Recorded::dropped) changed();
    return r;
  }

  template <class T>
  void write_fixed(const std::string &name, const std::vector<T> &values, const H5mdWriter::Shape &shape) {
    const std::string path = "observables/" + name;
    std::vector<hsize_t> dims(shape.begin(), shape.end());
    if (dims.empty()) dims.push_back(values.size());
    if (count_of(shape.empty() ? H5mdWriter::Shape{values.size()} : shape) != values.size())
      throw std::runtime_error("HDF5: '" + path + "': " + std::to_string(values.size()) +
                               " values for shape " + shape_text(shape));
    const auto [parent, leaf] = split_leaf(path);
    h5::Id group = h5::require_group(open_file(), parent);
    if (H5Lexists(group, leaf.c_str(), H5P_DEFAULT) > 0) H5Ldelete(group, leaf.c_str(), H5P_DEFAULT);
    h5::write_dataset(group, leaf, h5::native_type<T>(), dims, values.data());
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

std::string default_author() {
  for (const char *var : {"DYNHET_AUTHOR", "USER"})
    if (const char *v = std::getenv(var); v && *v) return v;
  return "unknown";
}

H5mdWriter::H5mdWriter(const std::string &path, const std::string &creator_name,
                       const std::string &creator_version, const std::string &author,
                       const std::string &author_email)
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
  if (!author_email.empty()) h5::write_attr(who, "email", author_email);
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

void H5mdWriter::write_reanalysis(int64_t run_id, const std::string &analysis_file,
                                  const std::string &analysis_toml, const std::string &recorded_scene_toml) {
  h5::Id params = h5::require_group(impl_->open_file(), "parameters");
  h5::Id g = h5::require_group(params, "reanalysis");
  h5::write_string_dataset(g, "analysis_toml", analysis_toml);
  h5::write_string_dataset(g, "recorded_scene_toml", recorded_scene_toml);
  impl_->changed();
  set_attribute("parameters/reanalysis", "of_run_id", run_id);
  set_attribute("parameters/reanalysis", "analysis_file", analysis_file);
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

H5mdWriter::Recorded H5mdWriter::append_frame(const Stamp &at, const std::vector<double> &unwrapped_xy,
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

  // One frame per chunk, split along particles beyond 64Ki of them. Image
  // shares position's step and time (hard links, as H5MD allows), so both
  // take or drop the record alike.
  const Shape row{n, 2};
  const std::vector<hsize_t> chunk{1, std::min<hsize_t>(n, 65536), 2};
  const std::string base = "particles/" + group;
  Series &pos = impl_->series_at(base + "/position", H5T_NATIVE_DOUBLE, row, chunk);
  Series &img = impl_->series_at(base + "/image", H5T_NATIVE_INT32, row, chunk, base + "/position");
  const Recorded r = impl_->append(pos, base + "/position", at, H5T_NATIVE_DOUBLE, position.data());
  impl_->append(img, base + "/image", at, H5T_NATIVE_INT32, image.data());
  if (r != Recorded::dropped) impl_->changed();
  return r;
}

H5mdWriter::Recorded H5mdWriter::append_observable(const std::string &path, const Stamp &at, const double *v,
                                                   const Shape &shape) {
  return impl_->append_observable(path, at, v, shape);
}
H5mdWriter::Recorded H5mdWriter::append_observable(const std::string &path, const Stamp &at, const int32_t *v,
                                                   const Shape &shape) {
  return impl_->append_observable(path, at, v, shape);
}
H5mdWriter::Recorded H5mdWriter::append_observable(const std::string &path, const Stamp &at, const int64_t *v,
                                                   const Shape &shape) {
  return impl_->append_observable(path, at, v, shape);
}

void H5mdWriter::write_fixed(const std::string &path, const std::vector<double> &values, const Shape &shape) {
  impl_->write_fixed(path, values, shape);
}
void H5mdWriter::write_fixed(const std::string &path, const std::vector<int32_t> &values,
                             const Shape &shape) {
  impl_->write_fixed(path, values, shape);
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
