# The Debian 12 packages (cpack -G DEB in a tree configured with
# -DCMAKE_INSTALL_PREFIX=/usr; scripts/package.sh), split as Debian splits a library:
#   finskit          finsd (+ systemd unit, /etc/finskit/finsd.toml), fins, fins-bridge
#                    (+ unit, /etc/finskit/fins-bridge.toml), docs, man
#                    pages, bash completions
# Each carries /usr/share/doc/PKG/copyright and changelog.gz (FinsDebian.cmake).
#   libfins0.1       libfins.so.0.1 (the SONAME while 0.x; see FinsPackage.cmake)
#   libfins-dev      headers, libfins.a, libfins.so, CMake and pkg-config files, API
#                    reference, examples
#   python3-finskit  the finskit module and its pytest plugin (when FINS_PYTHON)
install(FILES ${PROJECT_SOURCE_DIR}/packaging/finsd.service
  DESTINATION lib/systemd/system COMPONENT runtime)
# fins-bridge (docs/bridge.md): the program, its unit (not enabled by postinst: it needs
# a configured PLC list and broker) and /etc/finskit/fins-bridge.toml (a conffile).
install(TARGETS fins-bridge RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR} COMPONENT runtime)
install(FILES ${PROJECT_SOURCE_DIR}/packaging/fins-bridge.service
  DESTINATION lib/systemd/system COMPONENT runtime)
# /etc/finskit/finsd.toml (file(INSTALL) adds DESTDIR) when the prefix (at install time: cpack, --prefix) is /usr,
# as GNUInstallDirs does; <prefix>/etc/finskit otherwise, never the host's /etc.
install(CODE "
  if(CMAKE_INSTALL_PREFIX STREQUAL \"/usr\")
    set(fins_etc /etc)
  else()
    set(fins_etc \"\${CMAKE_INSTALL_PREFIX}/etc\")
  endif()
  file(INSTALL \"${PROJECT_SOURCE_DIR}/packaging/finsd.toml\"
       \"${PROJECT_SOURCE_DIR}/packaging/fins-bridge.toml\"
       DESTINATION \"\${fins_etc}/finskit\")" COMPONENT runtime)

set(CPACK_GENERATOR DEB)
# Install with DESTDIR and the real prefix, so the rule for /etc above sees /usr.
set(CPACK_SET_DESTDIR ON)
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
set(CPACK_PACKAGE_NAME finskit)
set(CPACK_PACKAGE_VENDOR finskit)
set(CPACK_PACKAGE_CONTACT "finskit maintainers <finskit-maintainers@example.org>")
set(CPACK_DEB_COMPONENT_INSTALL ON)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
# A cross build's packages are for its target (dpkg's name for the architecture).
if(CMAKE_CROSSCOMPILING AND CMAKE_SYSTEM_PROCESSOR STREQUAL aarch64)
  set(CPACK_DEBIAN_PACKAGE_ARCHITECTURE arm64)
endif()
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
set(CPACK_DEBIAN_PACKAGE_CONTROL_STRICT_PERMISSION ON)
# Debian policy 10.1-10.2 (lintian errors otherwise): stripped binaries, a shlibs file
# and the ldconfig trigger for the shared library.
set(CPACK_STRIP_FILES ON)
set(CPACK_DEBIAN_PACKAGE_GENERATE_SHLIBS ON)
set(CPACK_DEBIAN_PACKAGE_GENERATE_SHLIBS_POLICY ">=")
set(CPACK_COMPONENTS_ALL runtime lib dev)

set(CPACK_DEBIAN_RUNTIME_PACKAGE_NAME finskit)
set(CPACK_DEBIAN_RUNTIME_PACKAGE_SECTION net)
# Descriptions: the first line is the synopsis; CPack indents the others by one space
# (Debian's continuation lines), so they start at column 0 here, "." for a blank line.
set(CPACK_COMPONENT_RUNTIME_DESCRIPTION "Omron FINS virtual PLC (finsd service) and command-line client
finsd answers FINS/UDP and FINS/TCP like a CS/CJ CPU Unit, end code for end
code, as a hardened systemd service (config /etc/finskit/finsd.toml,
127.0.0.1:9600); fins reads, writes and probes a PLC or finsd.")
set(CPACK_DEBIAN_RUNTIME_PACKAGE_CONTROL_EXTRA
  ${PROJECT_SOURCE_DIR}/packaging/conffiles ${PROJECT_SOURCE_DIR}/packaging/postinst
  ${PROJECT_SOURCE_DIR}/packaging/prerm ${PROJECT_SOURCE_DIR}/packaging/postrm)

set(CPACK_DEBIAN_LIB_PACKAGE_NAME libfins${FINS_SOVERSION})
set(CPACK_DEBIAN_LIB_PACKAGE_SECTION libs)
set(CPACK_DEBIAN_LIB_PACKAGE_CONTROL_EXTRA ${PROJECT_SOURCE_DIR}/packaging/libfins/triggers)
set(CPACK_COMPONENT_LIB_DESCRIPTION "Omron FINS protocol library (libfins)
The FINS frame codec for the W342 command set, end codes as std::error_code,
PLC address strings, FINS/UDP and FINS/TCP transports and a pipelining client.")

set(CPACK_DEBIAN_DEV_PACKAGE_NAME libfins-dev)
set(CPACK_DEBIAN_DEV_PACKAGE_SECTION libdevel)
set(CPACK_DEBIAN_DEV_PACKAGE_DEPENDS
  "libfins${FINS_SOVERSION} (= ${PROJECT_VERSION}), libexpected-dev, libfmt-dev")
set(CPACK_COMPONENT_DEV_DESCRIPTION "Omron FINS protocol library (development files)
Headers, the static library, find_package(fins), fins.pc and fins-static.pc,
the API reference and example programs for libfins.")

if(FINS_PYTHON)
  list(APPEND CPACK_COMPONENTS_ALL python)
  set(CPACK_DEBIAN_PYTHON_PACKAGE_NAME python3-finskit)
  set(CPACK_DEBIAN_PYTHON_PACKAGE_SECTION python)
  set(CPACK_DEBIAN_PYTHON_PACKAGE_SUGGESTS python3-pytest)
  # The extension is built for this interpreter's ABI only.
  math(EXPR fins_python_next "${Python3_VERSION_MINOR} + 1")
  set(CPACK_DEBIAN_PYTHON_PACKAGE_DEPENDS
    "python3 (>= ${Python3_VERSION_MAJOR}.${Python3_VERSION_MINOR}), python3 (<< ${Python3_VERSION_MAJOR}.${fins_python_next})")
  set(CPACK_COMPONENT_PYTHON_DESCRIPTION "Omron FINS client and virtual PLC for Python (finskit)
finskit.Client talks FINS/UDP and FINS/TCP; finskit.VirtualPlc runs finsd
in-process; the virtual_plc pytest fixture gives each test a running virtual
PLC.
.
The extension is built for Debian's /usr/bin/python3 (this Python version
only): it does not load in another interpreter, such as a venv or pyenv Python
of another version.")
endif()
# Each package's copyright and changelog.gz (FinsDebian.cmake).
foreach(component runtime lib dev python)
  string(TOUPPER ${component} upper)
  if(component IN_LIST CPACK_COMPONENTS_ALL)
    fins_package_docs(${component} ${CPACK_DEBIAN_${upper}_PACKAGE_NAME})
  endif()
endforeach()
include(CPack)
