// Writes one run to an HDF5 file in the H5MD 1.1 layout
// (https://www.nongnu.org/h5md/h5md.html). HDF5's C API only, no LCM.
//
//   /h5md                      attr version = int32[2] {1, 1}
//   /h5md/creator              attrs name, version
//   /h5md/author               attrs name (and email, if given)
//   /parameters/scene_toml     the whole scene text (string)
//   /parameters/<table>        one attribute per TOML key, native types
//   /particles/<g>/box         attrs dimension = 2, boundary = [periodic, periodic];
//                              dataset edges = [L, L]
//   /particles/<g>/species     int32[N]
//   /particles/<g>/position    {step, time, value (frames, N, 2) folded into [0, L)}
//   /particles/<g>/image       {step, time: hard links to position's; value (frames, N, 2) int32}
//                              so that unwrapped = position + image * L
//   /observables/<path>        {step, time, value (records, record shape...)}
//
// H5MD's rules, kept by the writer for every file: every string (attribute
// or dataset) is a fixed-length string; in every time series step strictly
// increases (a record whose step is not above the last is dropped, or
// replaces the last record of the same step when asked to); a record keeps
// the shape it is given ({} one number, {n}, {a, b}, ...).
//
// Every append is flushed (unless auto flush is turned off), and the
// metadata cache never writes between flushes, so a writer killed with
// SIGKILL leaves the file as of its last flush, readable by h5py and
// h5dump. Every HDF5 failure throws std::runtime_error naming the path and
// carrying HDF5's own messages; the constructor turns off HDF5's printing
// of its error stack for the whole process.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace dynhet {

// The author when none is given: $DYNHET_AUTHOR, else $USER, else "unknown".
std::string default_author();

class H5mdWriter {
public:
  // Where a record sits in its time series: step (strictly increasing along
  // the series) and time. A record whose step is not above the series' last
  // step is dropped, unless `replace` is set and the step equals the last:
  // then it overwrites the last record.
  struct Stamp {
    int64_t step;
    double time;
    bool replace = false;
  };
  enum class Recorded { appended, replaced, dropped };
  // A record's dimensions: {} one number, {n}, {a, b}, ... (C order).
  using Shape = std::vector<size_t>;

  // Creates (or truncates) `path` and writes the h5md group. An empty
  // author means default_author(); an empty email writes none.
  H5mdWriter(const std::string &path, const std::string &creator_name, const std::string &creator_version,
             const std::string &author = "", const std::string &author_email = "");
  ~H5mdWriter(); // closes, swallowing errors; call close() to see them
  H5mdWriter(H5mdWriter &&) noexcept;
  H5mdWriter &operator=(H5mdWriter &&) noexcept;
  H5mdWriter(const H5mdWriter &) = delete;
  H5mdWriter &operator=(const H5mdWriter &) = delete;

  const std::string &path() const;

  // parameters/scene_toml holds the text; parameters/<table> one attribute
  // per key. The text is kept even when it is not valid TOML, then this
  // throws.
  void write_parameters(const std::string &scene_toml);
  // A re-analysis of recorded run `run_id` (dynhet/reanalysis.hpp):
  // parameters/reanalysis says so, with the analysis file's name
  // (attributes of_run_id, analysis_file) and text (analysis_toml) and the
  // recorded scene (recorded_scene_toml); parameters/scene_toml holds the
  // scene the re-analysis went by.
  void write_reanalysis(int64_t run_id, const std::string &analysis_file, const std::string &analysis_toml,
                        const std::string &recorded_scene_toml);

  // particles/<group>/{box, species} for a square periodic 2D box of side
  // `box_length`. Must come before append_frame for that group.
  void set_particles(const std::string &group, double box_length, const std::vector<int32_t> &species);
  void set_particles(const std::string &group, double box_length, const std::vector<int8_t> &species);

  // One frame of unwrapped positions x0 y0 x1 y1 ... (2N values), stored
  // as position folded into the box plus the image count; image shares
  // position's step and time.
  Recorded append_frame(const Stamp &at, const std::vector<double> &unwrapped_xy,
                        const std::string &group = "all");
  Recorded append_frame(int64_t step, double time, const std::vector<double> &unwrapped_xy,
                        const std::string &group = "all") {
    return append_frame(Stamp{step, time}, unwrapped_xy, group);
  }

  // One record of the time series observables/<path>, of `shape` (fixed by
  // the first append; its product is the number of values read from v).
  Recorded append_observable(const std::string &path, const Stamp &at, const double *v, const Shape &shape);
  Recorded append_observable(const std::string &path, const Stamp &at, const int32_t *v, const Shape &shape);
  Recorded append_observable(const std::string &path, const Stamp &at, const int64_t *v, const Shape &shape);
  // A one-dimensional record (shape {v.size()}) and a single number (shape {}).
  template <class T>
  Recorded append_observable(const std::string &path, const Stamp &at, const std::vector<T> &v) {
    return append_observable(path, at, v.data(), Shape{v.size()});
  }
  template <class T> Recorded append_scalar(const std::string &path, const Stamp &at, const T &v) {
    return append_observable(path, at, &v, Shape{});
  }
  // n values, one number per record when n == 1, else shape {n}; never replaces.
  template <class T>
  Recorded append_observable(const std::string &path, int64_t step, double time, const T *v, size_t n) {
    return append_observable(path, Stamp{step, time}, v, n == 1 ? Shape{} : Shape{n});
  }
  template <class T>
  Recorded append_observable(const std::string &path, int64_t step, double time, const std::vector<T> &v) {
    return append_observable(path, step, time, v.data(), v.size());
  }

  // A plain dataset observables/<path>, written once (e.g. lag times), of
  // `shape` (default: one-dimensional).
  void write_fixed(const std::string &path, const std::vector<double> &values, const Shape &shape = {});
  void write_fixed(const std::string &path, const std::vector<int32_t> &values, const Shape &shape = {});

  // An attribute on the object at `object` (relative to the root, "" is
  // the root); a missing group is created, an existing attribute replaced.
  void set_attribute(const std::string &object, const std::string &name, int32_t value);
  void set_attribute(const std::string &object, const std::string &name, int64_t value);
  void set_attribute(const std::string &object, const std::string &name, double value);
  void set_attribute(const std::string &object, const std::string &name, const std::string &value);
  void set_attribute(const std::string &object, const std::string &name, const std::vector<double> &values);
  void set_attribute(const std::string &object, const std::string &name, const char *value) {
    set_attribute(object, name, std::string(value));
  }

  // H5Fflush of the whole file. Appends call it themselves while auto
  // flush is on (the default); a caller writing several records that
  // belong together can turn it off and flush once after them.
  void flush();
  void set_auto_flush(bool on);

  // Flushes and closes; later calls do nothing. Throws on failure.
  void close();

private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

} // namespace dynhet
