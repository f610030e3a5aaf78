// Small HDF5 helpers shared by the io files: a handle closed on scope exit, and a scope in which
// HDF5 does not print its error stack (our messages say what went wrong).
#pragma once

#include <hdf5.h>

namespace morphogen::io {

struct H5Handle {
  hid_t id;
  herr_t (*close)(hid_t);
  H5Handle(hid_t i, herr_t (*c)(hid_t)) : id(i), close(c) {}
  H5Handle(const H5Handle&) = delete;
  H5Handle& operator=(const H5Handle&) = delete;
  ~H5Handle() {
    if (id >= 0) close(id);
  }
  bool ok() const { return id >= 0; }
  operator hid_t() const { return id; }
};

struct H5Silent {
  H5E_auto2_t func = nullptr;
  void* data = nullptr;
  H5Silent() {
    H5Eget_auto2(H5E_DEFAULT, &func, &data);
    H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  }
  ~H5Silent() { H5Eset_auto2(H5E_DEFAULT, func, data); }
};

} // namespace morphogen::io
