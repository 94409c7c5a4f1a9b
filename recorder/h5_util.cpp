#include "h5_util.hpp"

#include <algorithm>
#include <stdexcept>

namespace dynhet::h5 {

namespace {

// Collects HDF5's error stack, outermost call first.
herr_t collect_error(unsigned n, const H5E_error2_t *e, void *out) {
  auto &text = *static_cast<std::string *>(out);
  if (n > 0) text += "; ";
  std::string desc = e->desc ? e->desc : "?";
  for (char &c : desc)
    if (c == '\n') c = ' '; // HDF5 puts a ctime() line break in some
  text += std::string(e->func_name ? e->func_name : "?") + ": " + desc;
  return 0;
}

// The path of an object in its file, for messages.
std::string name_of(hid_t obj) {
  char buf[512];
  const ssize_t n = H5Iget_name(obj, buf, sizeof buf);
  return n > 0 ? std::string(buf) : std::string("?");
}

std::string child_path(hid_t loc, const std::string &name) {
  std::string parent = name_of(loc);
  return parent == "/" ? "/" + name : parent + "/" + name;
}

// The leading components of a/b/c: "a", "a/b", "a/b/c".
std::vector<std::string> prefixes(const std::string &path) {
  std::vector<std::string> out;
  size_t pos = 0;
  while (pos <= path.size()) {
    size_t slash = path.find('/', pos);
    if (slash == std::string::npos) slash = path.size();
    if (slash > pos) out.push_back(path.substr(0, slash));
    pos = slash + 1;
  }
  return out;
}

Id make_space(const std::vector<hsize_t> &dims, const std::string &path) {
  hid_t s = dims.empty() ? H5Screate(H5S_SCALAR)
                         : H5Screate_simple(static_cast<int>(dims.size()), dims.data(), nullptr);
  return Id(check(s, "cannot make a dataspace for", path));
}

void write_attr_in(hid_t obj, const std::string &name, hid_t type, hid_t space, const void *data) {
  const std::string where = "attribute " + name + " of";
  if (H5Aexists(obj, name.c_str()) > 0)
    check_status(H5Adelete(obj, name.c_str()), ("cannot replace " + where).c_str(), name_of(obj));
  Id attr(check(H5Acreate2(obj, name.c_str(), type, space, H5P_DEFAULT, H5P_DEFAULT),
                ("cannot create " + where).c_str(), name_of(obj)));
  if (data) check_status(H5Awrite(attr, type, data), ("cannot write " + where).c_str(), name_of(obj));
}

} // namespace

void silence_errors() { H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr); }

void fail(const std::string &what, const std::string &path) {
  std::string detail;
  H5Ewalk2(H5E_DEFAULT, H5E_WALK_DOWNWARD, collect_error, &detail);
  H5Eclear2(H5E_DEFAULT);
  throw std::runtime_error("HDF5: " + what + " '" + path + "'" + (detail.empty() ? "" : ": " + detail));
}

Id &Id::operator=(Id &&other) noexcept {
  if (this != &other) {
    reset();
    id_ = other.release();
  }
  return *this;
}

hid_t Id::release() {
  hid_t id = id_;
  id_ = H5I_INVALID_HID;
  return id;
}

void Id::reset() {
  if (id_ < 0) return;
  switch (H5Iget_type(id_)) {
  case H5I_FILE:
    H5Fclose(id_);
    break;
  case H5I_GROUP:
  case H5I_DATASET:
    H5Oclose(id_);
    break;
  case H5I_DATATYPE:
    H5Tclose(id_);
    break;
  case H5I_DATASPACE:
    H5Sclose(id_);
    break;
  case H5I_ATTR:
    H5Aclose(id_);
    break;
  case H5I_GENPROP_LST:
    H5Pclose(id_);
    break;
  default:
    break;
  }
  id_ = H5I_INVALID_HID;
}

Id string_type(size_t size, const std::string &text) {
  Id t(check(H5Tcopy(H5T_C_S1), "cannot copy", "string type"));
  check_status(H5Tset_size(t, std::max<size_t>(size, 1)), "cannot size", "string type");
  check_status(H5Tset_strpad(t, H5T_STR_NULLPAD), "cannot set NULLPAD on", "string type");
  const bool ascii = std::all_of(text.begin(), text.end(), [](char c) { return (c & 0x80) == 0; });
  check_status(H5Tset_cset(t, ascii ? H5T_CSET_ASCII : H5T_CSET_UTF8), "cannot set the character set of",
               "string type");
  return t;
}

Id bool_type() {
  Id t(check(H5Tenum_create(H5T_NATIVE_INT8), "cannot create", "bool type"));
  const int8_t no = 0, yes = 1;
  check_status(H5Tenum_insert(t, "FALSE", &no), "cannot insert FALSE in", "bool type");
  check_status(H5Tenum_insert(t, "TRUE", &yes), "cannot insert TRUE in", "bool type");
  return t;
}

bool exists(hid_t loc, const std::string &path) {
  for (const std::string &p : prefixes(path))
    if (H5Lexists(loc, p.c_str(), H5P_DEFAULT) <= 0) return false;
  return true;
}

Id require_group(hid_t loc, const std::string &path) {
  if (path.empty()) return Id(check(H5Gopen2(loc, ".", H5P_DEFAULT), "cannot open", name_of(loc)));
  for (const std::string &p : prefixes(path)) {
    if (H5Lexists(loc, p.c_str(), H5P_DEFAULT) > 0) continue;
    Id g(check(H5Gcreate2(loc, p.c_str(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), "cannot create group",
               child_path(loc, p)));
  }
  return Id(check(H5Gopen2(loc, path.c_str(), H5P_DEFAULT), "cannot open group", child_path(loc, path)));
}

void write_attr(hid_t obj, const std::string &name, hid_t type, const std::vector<hsize_t> &dims,
                const void *data) {
  Id space = make_space(dims, name_of(obj));
  write_attr_in(obj, name, type, space, data);
}

void write_attr(hid_t obj, const std::string &name, const std::string &value) {
  // c_str(): an empty string is one NUL byte, the smallest fixed-length string.
  write_attr(obj, name, string_type(value.size(), value), {}, value.c_str());
}

void write_attr(hid_t obj, const std::string &name, const std::vector<std::string> &values) {
  size_t width = 1;
  std::string all;
  for (const std::string &v : values) width = std::max(width, v.size()), all += v;
  std::vector<char> padded(values.size() * width, '\0');
  for (size_t i = 0; i < values.size(); ++i)
    std::copy(values[i].begin(), values[i].end(), &padded[i * width]);
  write_attr(obj, name, string_type(width, all), {values.size()}, padded.data());
}

void write_bool_attr(hid_t obj, const std::string &name, const std::vector<bool> &values, bool scalar) {
  std::vector<int8_t> v(values.begin(), values.end());
  std::vector<hsize_t> dims;
  if (!scalar) dims.push_back(v.size());
  write_attr(obj, name, bool_type(), dims, v.data());
}

void write_empty_attr(hid_t obj, const std::string &name) {
  Id space(check(H5Screate(H5S_NULL), "cannot make a null dataspace for", name_of(obj)));
  write_attr_in(obj, name, H5T_NATIVE_DOUBLE, space, nullptr);
}

void write_dataset(hid_t loc, const std::string &name, hid_t type, const std::vector<hsize_t> &dims,
                   const void *data) {
  const std::string path = child_path(loc, name);
  Id space = make_space(dims, path);
  Id d(check(H5Dcreate2(loc, name.c_str(), type, space, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT),
             "cannot create dataset", path));
  check_status(H5Dwrite(d, type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data), "cannot write", path);
}

void write_string_dataset(hid_t loc, const std::string &name, const std::string &text) {
  write_dataset(loc, name, string_type(text.size(), text), {}, text.c_str());
}

Id create_growing(hid_t loc, const std::string &name, hid_t type, const std::vector<hsize_t> &row_shape,
                  const std::vector<hsize_t> &chunk) {
  const std::string path = child_path(loc, name);
  std::vector<hsize_t> dims{0}, max_dims{H5S_UNLIMITED};
  dims.insert(dims.end(), row_shape.begin(), row_shape.end());
  max_dims.insert(max_dims.end(), row_shape.begin(), row_shape.end());
  const int rank = static_cast<int>(dims.size());
  Id space(check(H5Screate_simple(rank, dims.data(), max_dims.data()), "cannot shape", path));
  Id dcpl(check(H5Pcreate(H5P_DATASET_CREATE), "cannot make properties for", path));
  check_status(H5Pset_chunk(dcpl, rank, chunk.data()), "cannot set chunks of", path);
  return Id(check(H5Dcreate2(loc, name.c_str(), type, space, H5P_DEFAULT, dcpl, H5P_DEFAULT),
                  "cannot create dataset", path));
}

void append_row(hid_t dset, hid_t mem_type, const void *data, const std::string &path) {
  Id space(check(H5Dget_space(dset), "cannot get the shape of", path));
  const int rank = H5Sget_simple_extent_ndims(space);
  std::vector<hsize_t> dims(rank);
  H5Sget_simple_extent_dims(space, dims.data(), nullptr);

  // Grow by one record, then write into that last record.
  std::vector<hsize_t> start(rank, 0), count = dims;
  start[0] = dims[0];
  count[0] = 1;
  dims[0] += 1;
  check_status(H5Dset_extent(dset, dims.data()), "cannot extend", path);
  Id file_space(check(H5Dget_space(dset), "cannot get the shape of", path));
  check_status(H5Sselect_hyperslab(file_space, H5S_SELECT_SET, start.data(), nullptr, count.data(), nullptr),
               "cannot select the new record of", path);
  Id mem_space(check(H5Screate_simple(rank, count.data(), nullptr), "cannot shape", path));
  check_status(H5Dwrite(dset, mem_type, mem_space, file_space, H5P_DEFAULT, data), "cannot append to", path);
}

void write_row(hid_t dset, hsize_t index, hid_t mem_type, const void *data, const std::string &path) {
  Id file_space(check(H5Dget_space(dset), "cannot get the shape of", path));
  const int rank = H5Sget_simple_extent_ndims(file_space);
  std::vector<hsize_t> dims(rank);
  H5Sget_simple_extent_dims(file_space, dims.data(), nullptr);
  if (index >= dims[0]) fail("no record " + std::to_string(index) + " to overwrite in", path);
  std::vector<hsize_t> start(rank, 0), count = dims;
  start[0] = index;
  count[0] = 1;
  check_status(H5Sselect_hyperslab(file_space, H5S_SELECT_SET, start.data(), nullptr, count.data(), nullptr),
               "cannot select a record of", path);
  Id mem_space(check(H5Screate_simple(rank, count.data(), nullptr), "cannot shape", path));
  check_status(H5Dwrite(dset, mem_type, mem_space, file_space, H5P_DEFAULT, data),
               "cannot overwrite a record of", path);
}

} // namespace dynhet::h5
