// fmt's implementation, compiled once for the Windows cross build (cmake/FinsWindowsDeps.cmake).
// Debian ships fmt's headers but builds libfmt for Linux only. Header-only mode
// (FMT_HEADER_ONLY) makes <fmt/core.h> pull in <fmt/format.h> and <fmt/format-inl.h>:
// every one of the tree's files then compiled fmt's implementation again, about 6 s of
// MinGW -O3 each (docs/windows.md). Here the non-template functions are defined once
// (format-inl.h without FMT_HEADER_ONLY), with the template instances that the headers
// declare and leave to the library (fmt 9.1: format.h's "extern template"s and the
// declared-only templates: dragonbox, locale_ref, buffer::append, vformat_to).
#include <fmt/format-inl.h>

FMT_BEGIN_NAMESPACE
namespace detail {

template FMT_API auto dragonbox::to_decimal(float x) noexcept -> dragonbox::decimal_fp<float>;
template FMT_API auto dragonbox::to_decimal(double x) noexcept -> dragonbox::decimal_fp<double>;

template FMT_API locale_ref::locale_ref(const std::locale& loc);
template FMT_API auto locale_ref::get<std::locale>() const -> std::locale;

template FMT_API auto thousands_sep_impl(locale_ref) -> thousands_sep_result<char>;
template FMT_API auto decimal_point_impl(locale_ref) -> char;
template FMT_API void buffer<char>::append(const char*, const char*);
template FMT_API void vformat_to(buffer<char>&, string_view,
                                 basic_format_args<FMT_BUFFER_CONTEXT(char)>, locale_ref);

template FMT_API auto thousands_sep_impl(locale_ref) -> thousands_sep_result<wchar_t>;
template FMT_API auto decimal_point_impl(locale_ref) -> wchar_t;
template FMT_API void buffer<wchar_t>::append(const wchar_t*, const wchar_t*);

}  // namespace detail
FMT_END_NAMESPACE
