# The Debian 12 package (cpack -G DEB in a tree configured with
# -DCMAKE_INSTALL_PREFIX=/usr; scripts/package.sh). One package, finskit: finsd and its
# systemd unit and /etc/finskit/finsd.toml, fins, libfins (shared + static), headers,
# CMake and pkg-config files, docs, and the finskit Python module when built.
install(FILES ${PROJECT_SOURCE_DIR}/packaging/finsd.service
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
       DESTINATION \"\${fins_etc}/finskit\")" COMPONENT runtime)

set(CPACK_GENERATOR DEB)
# Install with DESTDIR and the real prefix, so the rule for /etc above sees /usr.
set(CPACK_SET_DESTDIR ON)
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
set(CPACK_PACKAGE_NAME finskit)
set(CPACK_PACKAGE_VENDOR finskit)
set(CPACK_PACKAGE_CONTACT "finskit maintainers <finskit@localhost>")
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY
  "Omron FINS protocol: libfins, the finsd virtual PLC and the fins CLI")
set(CPACK_PACKAGE_DESCRIPTION
  "libfins (codec, FINS/UDP and FINS/TCP transports, pipelining client) with headers,\n\
CMake and pkg-config files; finsd, a virtual CS/CJ CPU Unit, as a systemd service;\n\
fins, a command-line FINS client; and the finskit Python module.")
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_SECTION net)
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
set(CPACK_DEBIAN_PACKAGE_DEPENDS "libexpected-dev, libfmt-dev")
if(FINS_PYTHON)
  # The extension is built for this interpreter's ABI only.
  math(EXPR fins_python_next "${Python3_VERSION_MINOR} + 1")
  string(APPEND CPACK_DEBIAN_PACKAGE_DEPENDS
    ", python3 (>= ${Python3_VERSION_MAJOR}.${Python3_VERSION_MINOR}),"
    " python3 (<< ${Python3_VERSION_MAJOR}.${fins_python_next})")
endif()
set(CPACK_DEBIAN_PACKAGE_CONTROL_EXTRA
  ${PROJECT_SOURCE_DIR}/packaging/conffiles ${PROJECT_SOURCE_DIR}/packaging/postinst
  ${PROJECT_SOURCE_DIR}/packaging/prerm ${PROJECT_SOURCE_DIR}/packaging/postrm)
set(CPACK_DEBIAN_PACKAGE_CONTROL_STRICT_PERMISSION ON)
include(CPack)
