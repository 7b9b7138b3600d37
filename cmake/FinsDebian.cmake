# What a Debian package carries beside the programs: for each package its DEP-5
# copyright and gzip'd Debian changelog in /usr/share/doc/PKG/, the man pages fins(1),
# finsd(8) and fins-bridge(8) (help2man, from the programs' own --help and
# packaging/man/PROGRAM.h2m), and the bash completions of fins, finsd and fins-bridge.
# Included by FinsPackage.cmake; the package names come from there.

# One version: the changelog's top entry must be the project's.
file(STRINGS ${PROJECT_SOURCE_DIR}/packaging/changelog fins_changelog_top LIMIT_COUNT 1)
if(NOT fins_changelog_top MATCHES "^finskit \\(${PROJECT_VERSION}\\) ")
  message(FATAL_ERROR "packaging/changelog starts with '${fins_changelog_top}', not "
                      "finskit (${PROJECT_VERSION}): add an entry for this version")
endif()
set(fins_changelog_gz ${PROJECT_BINARY_DIR}/debian/changelog.gz)
add_custom_command(OUTPUT ${fins_changelog_gz}
  COMMAND ${CMAKE_COMMAND} -E make_directory ${PROJECT_BINARY_DIR}/debian
  COMMAND sh -c "gzip -9n -c '${PROJECT_SOURCE_DIR}/packaging/changelog' > '${fins_changelog_gz}'"
  DEPENDS ${PROJECT_SOURCE_DIR}/packaging/changelog VERBATIM)
add_custom_target(fins_changelog ALL DEPENDS ${fins_changelog_gz})

# fins_package_docs(COMPONENT PACKAGE): copyright and changelog.gz for one package.
function(fins_package_docs component package)
  install(FILES ${PROJECT_SOURCE_DIR}/packaging/copyright ${fins_changelog_gz}
    DESTINATION ${CMAKE_INSTALL_DATAROOTDIR}/doc/${package} COMPONENT ${component})
endfunction()

install(FILES ${PROJECT_SOURCE_DIR}/packaging/completions/finskit.bash
  DESTINATION ${CMAKE_INSTALL_DATAROOTDIR}/bash-completion/completions RENAME fins
  COMPONENT runtime)
install(FILES ${PROJECT_SOURCE_DIR}/packaging/completions/finskit.bash
  DESTINATION ${CMAKE_INSTALL_DATAROOTDIR}/bash-completion/completions RENAME finsd
  COMPONENT runtime)
install(FILES ${PROJECT_SOURCE_DIR}/packaging/completions/finskit.bash
  DESTINATION ${CMAKE_INSTALL_DATAROOTDIR}/bash-completion/completions RENAME fins-bridge
  COMPONENT runtime)

# Man pages: on where help2man is (scripts/debian-packages.txt), off in sanitizer and
# fuzz trees; scripts/package.sh asks for them.
find_program(FINS_HELP2MAN help2man)
set(fins_man_default OFF)
if(FINS_HELP2MAN AND NOT FINS_SANITIZE AND NOT FINS_FUZZ)
  set(fins_man_default ON)
endif()
option(FINS_MAN "Man pages fins.1, finsd.8 and fins-bridge.8 from --help (help2man)"
  ${fins_man_default})
if(FINS_MAN)
  if(NOT FINS_HELP2MAN)
    message(FATAL_ERROR "FINS_MAN needs help2man (apt install help2man)")
  endif()
  set(fins_man_pages)
  # help2man runs each program from PATH: the build's bin/, or in a cross build (arm64)
  # wrappers that run them under the emulator (qemu-user), so the pages are the same.
  set(fins_man_run_dir ${CMAKE_RUNTIME_OUTPUT_DIRECTORY})
  if(CMAKE_CROSSCOMPILING_EMULATOR)
    set(fins_man_run_dir ${PROJECT_BINARY_DIR}/emulated)
    string(JOIN " " fins_emulator ${CMAKE_CROSSCOMPILING_EMULATOR})
    foreach(program fins finsd fins-bridge)
      file(GENERATE OUTPUT ${fins_man_run_dir}/${program}
        CONTENT "#!/bin/sh\nexec ${fins_emulator} $<TARGET_FILE:${program}> \"$@\"\n"
        FILE_PERMISSIONS OWNER_READ OWNER_WRITE OWNER_EXECUTE GROUP_READ GROUP_EXECUTE
                         WORLD_READ WORLD_EXECUTE)
    endforeach()
  endif()
  foreach(page fins:1 finsd:8 fins-bridge:8)
    string(REPLACE ":" ";" page ${page})
    list(GET page 0 program)
    list(GET page 1 section)
    set(out ${PROJECT_BINARY_DIR}/man/${program}.${section})
    # Run from PATH so the usage line says "fins", not the build tree's path.
    add_custom_command(OUTPUT ${out}.gz
      COMMAND ${CMAKE_COMMAND} -E make_directory ${PROJECT_BINARY_DIR}/man
      COMMAND ${CMAKE_COMMAND} -E env PATH=${fins_man_run_dir}:$ENV{PATH}
              ${FINS_HELP2MAN} --no-info --section ${section} --version-option=--version
              --include ${PROJECT_SOURCE_DIR}/packaging/man/${program}.h2m --output ${out}
              ${program}
      COMMAND gzip -9nf ${out}
      DEPENDS ${program} ${PROJECT_SOURCE_DIR}/packaging/man/${program}.h2m
      COMMENT "help2man: ${program}(${section})" VERBATIM)
    list(APPEND fins_man_pages ${out}.gz)
    install(FILES ${out}.gz DESTINATION ${CMAKE_INSTALL_MANDIR}/man${section}
      COMPONENT runtime)
  endforeach()
  add_custom_target(fins_man ALL DEPENDS ${fins_man_pages})
endif()
