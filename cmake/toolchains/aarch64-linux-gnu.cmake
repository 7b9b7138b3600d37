# Linux arm64 (aarch64) from an x86-64 Debian host: Debian's cross compiler
# (crossbuild-essential-arm64) and the :arm64 -dev packages of Debian multiarch
# (scripts/debian-packages-arm64.txt), found under /usr/lib/aarch64-linux-gnu and
# /usr/include/aarch64-linux-gnu beside the host's. Programs (protoc) come from the host.
# Tests run under qemu-user (CMAKE_CROSSCOMPILING_EMULATOR), with the arm64 loader and
# libraries multiarch installed under / (hence -L /).
set(CMAKE_SYSTEM_NAME Linux)
set(CMAKE_SYSTEM_PROCESSOR aarch64)
set(CMAKE_LIBRARY_ARCHITECTURE aarch64-linux-gnu)
set(CMAKE_C_COMPILER aarch64-linux-gnu-gcc)
set(CMAKE_CXX_COMPILER aarch64-linux-gnu-g++)
set(CMAKE_CROSSCOMPILING_EMULATOR qemu-aarch64;-L;/)
# Libraries and headers of the target only; programs of the host only.
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
# pkg-config (libmosquitto) reads the arm64 .pc files only.
set(ENV{PKG_CONFIG_LIBDIR} /usr/lib/aarch64-linux-gnu/pkgconfig:/usr/share/pkgconfig)
set(ENV{PKG_CONFIG_SYSROOT_DIR} "")
