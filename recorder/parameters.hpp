// The scene's TOML as HDF5 attributes, internal to dynhet_h5md.
#pragma once

#include <hdf5.h>

#include <string>

namespace dynhet::h5 {

// One attribute per key with its native type; a table becomes a group of
// that name under `group` (nested tables nest). Throws std::runtime_error
// if the text is not valid TOML.
void write_toml_attributes(hid_t group, const std::string &toml_text);

} // namespace dynhet::h5
