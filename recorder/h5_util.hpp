// Small helpers over the HDF5 C API, internal to dynhet_h5md: ids that
// close themselves, failures turned into exceptions that name the object,
// attributes, and datasets that grow one record at a time.
#pragma once

#include <hdf5.h>

#include <cstdint>
#include <string>
#include <vector>

namespace dynhet::h5 {

// Stops HDF5 from printing its error stack; fail() puts it in the
// exception instead.
void silence_errors();

// Throws std::runtime_error "HDF5: <what> '<path>': <HDF5's own messages>".
[[noreturn]] void fail(const std::string &what, const std::string &path);

// Passes a valid id or status through; anything negative is a failure.
inline hid_t check(hid_t id, const char *what, const std::string &path) {
  if (id < 0) fail(what, path);
  return id;
}
inline void check_status(herr_t status, const char *what, const std::string &path) {
  if (status < 0) fail(what, path);
}

// An HDF5 id that is closed (with the close call matching its kind) when
// it goes out of scope.
class Id {
public:
  Id() = default;
  explicit Id(hid_t id) : id_(id) {}
  ~Id() { reset(); }
  Id(Id &&other) noexcept : id_(other.release()) {}
  Id &operator=(Id &&other) noexcept;
  Id(const Id &) = delete;
  Id &operator=(const Id &) = delete;

  operator hid_t() const { return id_; }
  bool valid() const { return id_ >= 0; }
  hid_t release();
  void reset();

private:
  hid_t id_ = H5I_INVALID_HID;
};

// The native HDF5 type of a C++ number type.
template <class T> hid_t native_type();
template <> inline hid_t native_type<int8_t>() { return H5T_NATIVE_INT8; }
template <> inline hid_t native_type<uint8_t>() { return H5T_NATIVE_UINT8; }
template <> inline hid_t native_type<int32_t>() { return H5T_NATIVE_INT32; }
template <> inline hid_t native_type<int64_t>() { return H5T_NATIVE_INT64; }
template <> inline hid_t native_type<double>() { return H5T_NATIVE_DOUBLE; }

// Fixed-length string type of `size` bytes (at least 1), NULLPAD: what
// H5MD asks for (h5py reads it as bytes). ASCII, or UTF-8 when `text`
// holds a byte above 127.
Id string_type(size_t size, const std::string &text);
// h5py's boolean: an int8 enum {FALSE = 0, TRUE = 1}.
Id bool_type();

// Does `path` (relative to loc, components separated by '/') exist?
bool exists(hid_t loc, const std::string &path);
// Opens the group at `path`, creating it and its parents if missing.
Id require_group(hid_t loc, const std::string &path);

// Attributes on an object; an existing attribute of that name is replaced.
void write_attr(hid_t obj, const std::string &name, hid_t type, const std::vector<hsize_t> &dims,
                const void *data);
template <class T> void write_attr(hid_t obj, const std::string &name, T value) {
  write_attr(obj, name, native_type<T>(), {}, &value);
}
template <class T> void write_attr(hid_t obj, const std::string &name, const std::vector<T> &values) {
  write_attr(obj, name, native_type<T>(), {values.size()}, values.data());
}
// Strings are fixed-length (string_type): one, or an array padded to the longest.
void write_attr(hid_t obj, const std::string &name, const std::string &value);
inline void write_attr(hid_t obj, const std::string &name, const char *value) {
  write_attr(obj, name, std::string(value));
}
void write_attr(hid_t obj, const std::string &name, const std::vector<std::string> &values);
void write_bool_attr(hid_t obj, const std::string &name, const std::vector<bool> &values, bool scalar);
// An attribute with no value (null dataspace), e.g. an empty TOML array.
void write_empty_attr(hid_t obj, const std::string &name);

// A fixed dataset written once.
void write_dataset(hid_t loc, const std::string &name, hid_t type, const std::vector<hsize_t> &dims,
                   const void *data);
void write_string_dataset(hid_t loc, const std::string &name, const std::string &text);

// A chunked dataset of shape (0, row_shape...) that grows along its first
// axis; `chunk` is the chunk shape (same rank).
Id create_growing(hid_t loc, const std::string &name, hid_t type, const std::vector<hsize_t> &row_shape,
                  const std::vector<hsize_t> &chunk);
// Appends one record (a full row of row_shape) read from `data` of `mem_type`.
void append_row(hid_t dset, hid_t mem_type, const void *data, const std::string &path);
// Overwrites record `index` (along the first axis) with `data`.
void write_row(hid_t dset, hsize_t index, hid_t mem_type, const void *data, const std::string &path);

} // namespace dynhet::h5
