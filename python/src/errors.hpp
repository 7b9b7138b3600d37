// How libfins failures reach Python. C++ code (often running with the GIL released)
// throws Failure; the translator registered by register_errors() raises, with the GIL:
//   FINS end code (category fins.end_code) -> finskit.FinsError(code, name, meaning)
//   ClientError::timeout                   -> TimeoutError
//   bad address / argument                 -> ValueError
//   anything else (connection, FINS/TCP)   -> ConnectionError
#pragma once

#include <stdexcept>
#include <string>
#include <system_error>

#include <pybind11/pybind11.h>

#include "fins/error.hpp"

namespace finskit {

struct Failure : std::runtime_error {
    Failure(std::error_code c, const std::string& context)
        : std::runtime_error(context + ": " + c.message()), code(c) {}
    std::error_code code;
};

// A ValueError for a bad argument caught before anything is sent.
struct BadArgument : std::invalid_argument {
    using std::invalid_argument::invalid_argument;
};

void register_errors(pybind11::module_& m);

template <class T>
T value_or_throw(fins::Result<T> r, const std::string& context) {
    if (!r) throw Failure(r.error(), context);
    if constexpr (!std::is_void_v<T>) return std::move(*r);
}

}  // namespace finskit
