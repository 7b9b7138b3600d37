// The finskit extension module (finskit._finskit); finskit/__init__.py re-exports it.
#include <pybind11/pybind11.h>

#include "errors.hpp"

namespace finskit {
void register_client(pybind11::module_& m);
void register_virtual_plc(pybind11::module_& m);
}  // namespace finskit

PYBIND11_MODULE(_finskit, m) {
    m.doc() = "Omron FINS for Python: libfins's client and finsd's virtual PLC.";
    finskit::register_errors(m);
    finskit::register_client(m);
    finskit::register_virtual_plc(m);
}
