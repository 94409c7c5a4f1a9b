// Reading an HDF5 file back in tests, with HDF5's C API only (not the
// writer's helpers), so that a round trip checks the file, not the code.
#pragma once

#include <hdf5.h>

#include <stdexcept>
#include <string>
#include <vector>

namespace h5read {

inline void ok(herr_t status, const std::string &what) {
  if (status < 0) throw std::runtime_error("HDF5 read failed: " + what);
}
inline hid_t ok_id(hid_t id, const std::string &what) {
  if (id < 0) throw std::runtime_error("HDF5 read failed: " + what);
  return id;
}

class File {
public:
  explicit File(const std::string &path)
      : id_(ok_id(H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), "open " + path)) {}
  ~File() { H5Fclose(id_); }
  File(const File &) = delete;
  File &operator=(const File &) = delete;
  operator hid_t() const { return id_; }

private:
  hid_t id_;
};

template <class T> hid_t native();
template <> inline hid_t native<int32_t>() { return H5T_NATIVE_INT32; }
template <> inline hid_t native<int64_t>() { return H5T_NATIVE_INT64; }
template <> inline hid_t native<int8_t>() { return H5T_NATIVE_INT8; }
template <> inline hid_t native<double>() { return H5T_NATIVE_DOUBLE; }

inline bool exists(hid_t file, const std::string &path) {
  return H5Oexists_by_name(file, path.c_str(), H5P_DEFAULT) > 0;
}

inline std::vector<hsize_t> shape_of_space(hid_t space) {
  std::vector<hsize_t> dims(H5Sget_simple_extent_ndims(space));
  H5Sget_simple_extent_dims(space, dims.data(), nullptr);
  return dims;
}

inline std::vector<hsize_t> shape(hid_t file, const std::string &path) {
  hid_t d = ok_id(H5Dopen2(file, path.c_str(), H5P_DEFAULT), "open " + path);
  hid_t s = H5Dget_space(d);
  std::vector<hsize_t> dims = shape_of_space(s);
  H5Sclose(s);
  H5Dclose(d);
  return dims;
}

// The whole dataset, converted to T, flattened in C order.
template <class T> std::vector<T> read(hid_t file, const std::string &path) {
  size_t n = 1;
  for (hsize_t d : shape(file, path)) n *= d;
  std::vector<T> out(n);
  hid_t d = ok_id(H5Dopen2(file, path.c_str(), H5P_DEFAULT), "open " + path);
  ok(H5Dread(d, native<T>(), H5S_ALL, H5S_ALL, H5P_DEFAULT, out.data()), "read " + path);
  H5Dclose(d);
  return out;
}

// The HDF5 type class and size of a dataset or attribute type.
struct TypeInfo {
  H5T_class_t cls;
  size_t size;
};
inline TypeInfo type_info(hid_t type) {
  TypeInfo t{H5Tget_class(type), H5Tget_size(type)};
  H5Tclose(type);
  return t;
}
inline TypeInfo dataset_type(hid_t file, const std::string &path) {
  hid_t d = ok_id(H5Dopen2(file, path.c_str(), H5P_DEFAULT), "open " + path);
  TypeInfo t = type_info(H5Dget_type(d));
  H5Dclose(d);
  return t;
}

// Strings as H5MD asks for them: fixed-length (any padding). A
// variable-length string throws, so that every string a test reads is
// checked to be fixed-length.
inline std::vector<std::string> read_fixed_strings(hid_t obj, hid_t space, bool attr) {
  const hssize_t n = H5Sget_simple_extent_npoints(space);
  // Read with the stored type itself: HDF5 does not convert ASCII <-> UTF-8.
  hid_t t = attr ? H5Aget_type(obj) : H5Dget_type(obj);
  if (H5Tget_class(t) != H5T_STRING || H5Tis_variable_str(t) != 0) {
    H5Tclose(t);
    throw std::runtime_error("not a fixed-length string");
  }
  const size_t width = H5Tget_size(t);
  std::vector<char> buf(static_cast<size_t>(n) * width);
  ok(attr ? H5Aread(obj, t, buf.data()) : H5Dread(obj, t, H5S_ALL, H5S_ALL, H5P_DEFAULT, buf.data()),
     "read strings");
  H5Tclose(t);
  std::vector<std::string> out;
  for (hssize_t i = 0; i < n; ++i) {
    std::string v(&buf[static_cast<size_t>(i) * width], width);
    out.push_back(v.substr(0, v.find('\0'))); // NULLPAD or NULLTERM
  }
  return out;
}

inline std::string read_string(hid_t file, const std::string &path) {
  hid_t d = ok_id(H5Dopen2(file, path.c_str(), H5P_DEFAULT), "open " + path);
  hid_t s = H5Dget_space(d);
  std::vector<std::string> v = read_fixed_strings(d, s, false);
  H5Sclose(s);
  H5Dclose(d);
  return v.at(0);
}

// Are the two paths links to one HDF5 object (hard links to the same
// dataset or group)? And how many hard links an object has.
struct ObjectInfo {
  bool valid;
  unsigned links;
#if H5_VERSION_GE(1, 12, 0)
  H5O_token_t token;
#else
  haddr_t addr;
#endif
};
inline ObjectInfo object_info(hid_t file, const std::string &path) {
  ObjectInfo o{};
#if H5_VERSION_GE(1, 12, 0)
  H5O_info2_t info;
  o.valid = H5Oget_info_by_name3(file, path.c_str(), &info, H5O_INFO_BASIC, H5P_DEFAULT) >= 0;
  o.token = info.token;
#else
  H5O_info_t info;
  o.valid = H5Oget_info_by_name2(file, path.c_str(), &info, H5O_INFO_BASIC, H5P_DEFAULT) >= 0;
  o.addr = info.addr;
#endif
  o.links = info.rc;
  if (!o.valid) throw std::runtime_error("HDF5 read failed: object info of " + path);
  return o;
}
inline bool same_object(hid_t file, const std::string &a, const std::string &b) {
  const ObjectInfo x = object_info(file, a), y = object_info(file, b);
#if H5_VERSION_GE(1, 12, 0)
  int cmp = 1;
  H5Otoken_cmp(file, &x.token, &y.token, &cmp);
  return cmp == 0;
#else
  return x.addr == y.addr;
#endif
}

// An attribute of the object at `obj_path` ("/" for the root).
class Attr {
public:
  Attr(hid_t file, const std::string &obj_path, const std::string &name)
      : id_(ok_id(H5Aopen_by_name(file, obj_path.c_str(), name.c_str(), H5P_DEFAULT, H5P_DEFAULT),
                  "open attribute " + obj_path + " " + name)) {}
  ~Attr() { H5Aclose(id_); }
  Attr(const Attr &) = delete;
  Attr &operator=(const Attr &) = delete;

  TypeInfo type() const { return type_info(H5Aget_type(id_)); }
  std::vector<hsize_t> shape() const {
    hid_t s = H5Aget_space(id_);
    std::vector<hsize_t> dims = shape_of_space(s);
    H5Sclose(s);
    return dims;
  }
  template <class T> std::vector<T> values() const {
    hid_t s = H5Aget_space(id_);
    std::vector<T> out(static_cast<size_t>(H5Sget_simple_extent_npoints(s)));
    H5Sclose(s);
    ok(H5Aread(id_, native<T>(), out.data()), "read attribute");
    return out;
  }
  // Read with the stored type (e.g. the int8 enum of a bool, which HDF5
  // does not convert to a plain integer).
  template <class T> std::vector<T> stored_values() const {
    hid_t s = H5Aget_space(id_);
    std::vector<T> out(static_cast<size_t>(H5Sget_simple_extent_npoints(s)));
    H5Sclose(s);
    hid_t t = H5Aget_type(id_);
    if (H5Tget_size(t) != sizeof(T)) throw std::runtime_error("stored type size differs");
    ok(H5Aread(id_, t, out.data()), "read attribute");
    H5Tclose(t);
    return out;
  }
  bool is_null() const {
    hid_t s = H5Aget_space(id_);
    const bool null = H5Sget_simple_extent_type(s) == H5S_NULL;
    H5Sclose(s);
    return null;
  }
  std::vector<std::string> strings() const {
    hid_t s = H5Aget_space(id_);
    std::vector<std::string> v = read_fixed_strings(id_, s, true);
    H5Sclose(s);
    return v;
  }

private:
  hid_t id_;
};

} // namespace h5read
