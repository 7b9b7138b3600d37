# shellcheck shell=bash disable=SC2034
# Sourced by scripts/build.sh and scripts/package.sh: the optimised trees' level (release,
# arm64, windows, the package), Release's -O3 unless FINS_OPT says otherwise
# (scripts/test.sh: -O1, to fit CI's time; docs/testing.md). Sets fins_release_opt to the
# CMake option.
fins_release_opt=("-DCMAKE_CXX_FLAGS_RELEASE=${FINS_OPT:--O3} -DNDEBUG")
