# The installable libfins and everything `cmake --install` / CPack ship.
#
# libfins is the client side of finskit: the codec (include/fins/*, src/codec), the
# transports and the client. It is built once, from the same objects the tests link,
# as a shared library (fins::fins, SONAME libfins.so.<major>[.<minor> while 0.x]) and a
# static one (fins::fins_static), both versioned by the one project(... VERSION). The
# virtual PLC and its server (src/plc, src/server) stay internal: their API is not
# stable yet; users get them as the finsd program and as finskit.VirtualPlc.
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

set(fins_parts fins_codec fins_engine fins_transport fins_client)
set(fins_objects)
foreach(part ${fins_parts})
  set_target_properties(${part} PROPERTIES POSITION_INDEPENDENT_CODE ON)
  list(APPEND fins_objects $<TARGET_OBJECTS:${part}>)
endforeach()
# Windows: fmt is compiled in this tree (cmake/FinsWindowsDeps.cmake), and libfins carries
# it; on Linux libfins links Debian's libfmt.
if(WIN32)
  list(APPEND fins_objects $<TARGET_OBJECTS:fins_win_fmt>)
  set(fins_fmt $<BUILD_INTERFACE:fmt::fmt>)
else()
  set(fins_fmt fmt::fmt)
endif()

# 0.x releases break the ABI at every minor version, so the SONAME carries it.
if(PROJECT_VERSION_MAJOR EQUAL 0)
  set(FINS_SOVERSION ${PROJECT_VERSION_MAJOR}.${PROJECT_VERSION_MINOR})
else()
  set(FINS_SOVERSION ${PROJECT_VERSION_MAJOR})
endif()

add_library(fins_shared SHARED ${fins_objects})
add_library(fins_static STATIC ${fins_objects})
set_target_properties(fins_shared PROPERTIES OUTPUT_NAME fins EXPORT_NAME fins
  VERSION ${PROJECT_VERSION} SOVERSION ${FINS_SOVERSION} LINKER_LANGUAGE CXX)
set_target_properties(fins_static PROPERTIES OUTPUT_NAME fins EXPORT_NAME fins_static
  LINKER_LANGUAGE CXX)
foreach(lib fins_shared fins_static)
  target_include_directories(${lib} PUBLIC
    $<BUILD_INTERFACE:${PROJECT_SOURCE_DIR}/include>
    $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>)
  target_compile_features(${lib} PUBLIC cxx_std_20)
  # The public headers use tl::expected (fins::Result); fmt and threads are used inside.
  target_link_libraries(${lib} PUBLIC tl::expected PRIVATE ${fins_fmt} Threads::Threads)
  if(WIN32)
    # Winsock 2 and its extensions, under Asio's sockets.
    target_link_libraries(${lib} PRIVATE ws2_32 mswsock)
  endif()
endforeach()
# MinGW: fins.dll exports every symbol, as libfins.so does (no dllexport annotations).
set_target_properties(fins_shared PROPERTIES WINDOWS_EXPORT_ALL_SYMBOLS ON)
add_library(fins::fins ALIAS fins_shared)
add_library(fins::fins_static ALIAS fins_static)

set(FINS_CMAKE_DIR ${CMAKE_INSTALL_LIBDIR}/cmake/fins)
install(TARGETS fins_shared fins_static EXPORT finsTargets
  LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR} COMPONENT lib NAMELINK_COMPONENT dev
  RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR} COMPONENT lib
  ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR} COMPONENT dev)
install(DIRECTORY ${PROJECT_SOURCE_DIR}/include/fins
  DESTINATION ${CMAKE_INSTALL_INCLUDEDIR} COMPONENT dev)
install(EXPORT finsTargets NAMESPACE fins:: DESTINATION ${FINS_CMAKE_DIR} COMPONENT dev)
configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/finsConfig.cmake.in
  ${PROJECT_BINARY_DIR}/finsConfig.cmake INSTALL_DESTINATION ${FINS_CMAKE_DIR})
# 0.x: only the same minor version is compatible (see FINS_SOVERSION).
write_basic_package_version_file(${PROJECT_BINARY_DIR}/finsConfigVersion.cmake
  COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/finsConfig.cmake ${PROJECT_BINARY_DIR}/finsConfigVersion.cmake
  DESTINATION ${FINS_CMAKE_DIR} COMPONENT dev)

# pkg-config: `pkg-config --cflags --libs fins` links libfins.so; `... fins-static`
# links libfins.a (`--static` cannot: -lfins takes the .so whenever both are there).
file(RELATIVE_PATH FINS_PC_TO_PREFIX /prefix/${CMAKE_INSTALL_LIBDIR}/pkgconfig /prefix)
foreach(pc fins fins-static)
  configure_file(${PROJECT_SOURCE_DIR}/cmake/${pc}.pc.in ${PROJECT_BINARY_DIR}/${pc}.pc @ONLY)
  install(FILES ${PROJECT_BINARY_DIR}/${pc}.pc
    DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig COMPONENT dev)
endforeach()

if(WIN32)
  # fins.exe; finsd.exe is installed by cmake/FinsWindowsPackage.cmake (docs/windows.md).
  install(TARGETS fins RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR} COMPONENT runtime)
else()
  install(TARGETS finsd fins RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR} COMPONENT runtime)
endif()
# README.md and its pages under docs/ keep their relative links.
install(FILES ${PROJECT_SOURCE_DIR}/README.md DESTINATION ${CMAKE_INSTALL_DOCDIR} COMPONENT runtime)
file(GLOB fins_doc_pages CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/docs/*.md)
install(FILES ${fins_doc_pages} DESTINATION ${CMAKE_INSTALL_DOCDIR}/docs COMPONENT runtime)
install(DIRECTORY ${PROJECT_SOURCE_DIR}/examples/ DESTINATION ${CMAKE_INSTALL_DOCDIR}/examples
  COMPONENT dev FILES_MATCHING PATTERN "*.cpp" PATTERN "*.toml" PATTERN "CMakeLists.txt")

# The API reference (Doxygen, docs/api): `fins_docs`, built by default when Doxygen is
# found (FINS_DOCS), installed with the docs.
find_package(Doxygen QUIET)
set(fins_docs_default OFF)
if(DOXYGEN_FOUND AND NOT FINS_FUZZ)
  set(fins_docs_default ON)
endif()
option(FINS_DOCS "Build the Doxygen API reference" ${fins_docs_default})
if(FINS_DOCS)
  find_package(Doxygen REQUIRED)
  configure_file(${PROJECT_SOURCE_DIR}/cmake/Doxyfile.in ${PROJECT_BINARY_DIR}/Doxyfile @ONLY)
  file(GLOB_RECURSE fins_public_headers CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/include/fins/*)
  add_custom_command(OUTPUT ${PROJECT_BINARY_DIR}/api/html/index.html
    COMMAND ${CMAKE_COMMAND} -E rm -rf ${PROJECT_BINARY_DIR}/api
    COMMAND Doxygen::doxygen ${PROJECT_BINARY_DIR}/Doxyfile
    DEPENDS ${fins_public_headers} ${PROJECT_SOURCE_DIR}/cmake/Doxyfile.in
            ${PROJECT_SOURCE_DIR}/cmake/doxygen-filter.sh ${PROJECT_SOURCE_DIR}/docs/api/mainpage.md
    COMMENT "Doxygen: libfins API reference" VERBATIM)
  add_custom_target(fins_docs ALL DEPENDS ${PROJECT_BINARY_DIR}/api/html/index.html)
  install(DIRECTORY ${PROJECT_BINARY_DIR}/api/html/ DESTINATION ${CMAKE_INSTALL_DOCDIR}/api
    COMPONENT dev)
endif()

# The finskit Python module (python/): on by default when pybind11 and the Python
# headers are found, off in sanitizer and fuzz builds (an instrumented extension cannot
# be loaded into an uninstrumented interpreter).
# A cross build (arm64, Windows) leaves it out: the host's interpreter cannot load it.
set(fins_python_default OFF)
if(NOT CMAKE_CROSSCOMPILING AND NOT FINS_SANITIZE AND NOT FINS_FUZZ)
  find_package(Python3 3.9 QUIET COMPONENTS Interpreter Development.Module)
  find_package(pybind11 CONFIG QUIET)
  if(Python3_FOUND AND pybind11_FOUND)
    set(fins_python_default ON)
  endif()
endif()
option(FINS_PYTHON "Build the finskit Python module (pybind11)" ${fins_python_default})
if(FINS_PYTHON)
  add_subdirectory(${PROJECT_SOURCE_DIR}/python ${PROJECT_BINARY_DIR}/python)
endif()

if(WIN32)
  include(${CMAKE_CURRENT_LIST_DIR}/FinsWindowsPackage.cmake)
else()
  include(${CMAKE_CURRENT_LIST_DIR}/FinsDebian.cmake)
  include(${CMAKE_CURRENT_LIST_DIR}/FinsCPack.cmake)
endif()
