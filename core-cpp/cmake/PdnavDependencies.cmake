# Third-party dependencies of the core. On the host they come from Debian packages
# (tools/setup installs them); on an Android workstation (NDK) the same versions are
# fetched, pinned by tag and hash, with FetchContent.
include(FetchContent)

# Eigen 3.4 (MPL-2.0), header only.
find_package(Eigen3 3.4 QUIET NO_MODULE)
if(NOT TARGET Eigen3::Eigen)
  FetchContent_Declare(eigen
    URL https://gitlab.com/libeigen/eigen/-/archive/3.4.0/eigen-3.4.0.tar.gz
    URL_HASH SHA256=8586084f71f9bde545ee7fa6d00288b264a2b7ac3607b974e54d13e7162c1c72)
  FetchContent_GetProperties(eigen)
  if(NOT eigen_POPULATED)
    FetchContent_Populate(eigen)
  endif()
  add_library(Eigen3::Eigen INTERFACE IMPORTED GLOBAL)
  target_include_directories(Eigen3::Eigen INTERFACE "${eigen_SOURCE_DIR}")
endif()

# fast_float (Apache-2.0/MIT/BSL), header only: locale-free, exact number parsing
# for the log, DEM and RINEX readers (libc++ in older NDKs lacks floating from_chars).
find_package(FastFloat QUIET)
if(NOT TARGET FastFloat::fast_float)
  FetchContent_Declare(fast_float
    GIT_REPOSITORY https://github.com/fastfloat/fast_float.git
    GIT_TAG v3.9.0  # same version as Debian bookworm's libfast-float-dev
    GIT_SHALLOW TRUE)
  FetchContent_GetProperties(fast_float)
  if(NOT fast_float_POPULATED)
    FetchContent_Populate(fast_float)
  endif()
  add_library(FastFloat::fast_float INTERFACE IMPORTED GLOBAL)
  target_include_directories(FastFloat::fast_float INTERFACE "${fast_float_SOURCE_DIR}/include")
endif()

# zlib: inflate for zipped recordings (Sensor Logger, phyphox exports; io/container.cpp).
# A system library of the Android NDK (libz.so in every sysroot) and Debian's zlib1g-dev on
# the host, so the same find_package works on both.
find_package(ZLIB REQUIRED)

if(NOT ANDROID)
  # Host-only tools (CLI, tests, benchmarks).
  find_package(CLI11 2.1 REQUIRED CONFIG)
  find_package(nlohmann_json 3.11 REQUIRED CONFIG)
  if(PDNAV_BUILD_TESTS)
    find_package(GTest 1.12 REQUIRED CONFIG)
  endif()
  if(PDNAV_BUILD_BENCHMARKS)
    find_package(benchmark 1.7 REQUIRED CONFIG)
  endif()
endif()
