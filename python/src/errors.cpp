#include "errors.hpp"

#include <string>

namespace py = pybind11;

namespace finskit {

namespace {

// Created once at import; the module keeps a reference for the interpreter's life.
PyObject* fins_error = nullptr;

void raise_end_code(const Failure& f) {
    const auto value = static_cast<std::uint16_t>(f.code.value());
    const auto* info = fins::find_end_code(value);
    py::object type = py::reinterpret_borrow<py::object>(fins_error);
    py::object error = type(f.what());
    error.attr("code") = value;
    error.attr("name") = info ? std::string(info->name) : std::string("unknown end code");
    error.attr("meaning") = info ? std::string(info->message) : f.code.message();
    PyErr_SetObject(fins_error, error.ptr());
}

}  // namespace

void register_errors(py::module_& m) {
    fins_error = PyErr_NewExceptionWithDoc(
        "finskit.FinsError",
        "The PLC answered a non-zero FINS end code (W342 5-1-3).\n\n"
        "Attributes: code (int, e.g. 0x2101), name (str, e.g. 'write not possible: "
        "read-only'), meaning (str, the manual's probable cause).",
        nullptr, nullptr);
    m.add_object("FinsError", py::handle(fins_error));
    py::register_exception_translator([](std::exception_ptr p) {
        try {
            if (p) std::rethrow_exception(p);
        } catch (const Failure& f) {
            if (f.code.category() == fins::end_code_category()) return raise_end_code(f);
            if (f.code == fins::ClientError::timeout)
                return PyErr_SetString(PyExc_TimeoutError, f.what());
            if (f.code == fins::ClientError::invalid_argument ||
                f.code.category() == fins::make_error_code(fins::AddressError::empty).category())
                return PyErr_SetString(PyExc_ValueError, f.what());
            PyErr_SetString(PyExc_ConnectionError, f.what());
        } catch (const BadArgument& e) {
            PyErr_SetString(PyExc_ValueError, e.what());
        }
    });
}

}  // namespace finskit
