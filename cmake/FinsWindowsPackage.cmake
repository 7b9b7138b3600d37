# The Windows release artifact (scripts/package.sh windows, docs/windows.md):
# finskit-VERSION-windows-x86_64.zip with bin/ (fins.exe, finsd.exe with the web page's
# assets compiled in, libfins.dll and the MinGW-w64
# runtime DLLs it uses), include/ (with
# tl/expected.hpp),
# lib/ (libfins.a, the import library libfins.dll.a, the CMake package and pkg-config
# files), the documentation and README-windows.txt.
# finsd.exe (cmake/FinsPackage.cmake installs fins.exe): linked statically, like fins.exe.
install(TARGETS finsd RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR} COMPONENT runtime)
install(FILES ${PROJECT_SOURCE_DIR}/packaging/windows/README-windows.txt
  DESTINATION . COMPONENT runtime)
# fins::Result is a tl::expected: its one header (CC0) ships beside ours, as no Windows
# package manager is assumed.
install(FILES /usr/include/tl/expected.hpp DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/tl COMPONENT dev)
# MinGW-w64's runtime, which libfins.dll and a user's MinGW-built program share.
foreach(dll libstdc++-6.dll libgcc_s_seh-1.dll libwinpthread-1.dll)
  execute_process(COMMAND ${CMAKE_CXX_COMPILER} -print-file-name=${dll}
                  OUTPUT_VARIABLE fins_runtime_dll OUTPUT_STRIP_TRAILING_WHITESPACE)
  if(NOT EXISTS "${fins_runtime_dll}")
    message(FATAL_ERROR "${dll} not found beside ${CMAKE_CXX_COMPILER}")
  endif()
  install(FILES ${fins_runtime_dll} DESTINATION ${CMAKE_INSTALL_BINDIR} COMPONENT lib)
endforeach()
set(CPACK_GENERATOR ZIP)
set(CPACK_PACKAGE_NAME finskit)
set(CPACK_PACKAGE_VENDOR finskit)
set(CPACK_PACKAGE_FILE_NAME finskit-${PROJECT_VERSION}-windows-x86_64)
set(CPACK_INCLUDE_TOPLEVEL_DIRECTORY ON)
set(CPACK_ARCHIVE_COMPONENT_INSTALL OFF)
include(CPack)
