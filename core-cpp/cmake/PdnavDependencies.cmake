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

# GeographicLib (MIT): the geodesic inverse problem (Karney 2013) behind geo::geodesic_inverse.
# Host: Debian's libgeographiclib-dev; NDK: the same version built statically from its tag
# (PDNAV_GEOGRAPHICLIB_FROM_SOURCE=ON tries that path on the host; with no network, point
# FETCHCONTENT_SOURCE_DIR_GEOGRAPHICLIB at a checkout of the tag).
if(ANDROID)
  set(_pdnav_gl_default ON)
else()
  set(_pdnav_gl_default OFF)
endif()
option(PDNAV_GEOGRAPHICLIB_FROM_SOURCE "build GeographicLib from its pinned tag (the NDK path)" ${_pdnav_gl_default})
if(NOT TARGET pdnav_geographiclib)
  add_library(pdnav_geographiclib INTERFACE)
  if(NOT PDNAV_GEOGRAPHICLIB_FROM_SOURCE)
    find_path(PDNAV_GEOGRAPHICLIB_INCLUDE GeographicLib/Geodesic.hpp)
    find_library(PDNAV_GEOGRAPHICLIB_LIBRARY GeographicLib)
    if(NOT PDNAV_GEOGRAPHICLIB_INCLUDE OR NOT PDNAV_GEOGRAPHICLIB_LIBRARY)
      message(FATAL_ERROR "pdnav: GeographicLib not found (tools/setup installs libgeographiclib-dev)")
    endif()
    target_include_directories(pdnav_geographiclib SYSTEM INTERFACE "${PDNAV_GEOGRAPHICLIB_INCLUDE}")
    target_link_libraries(pdnav_geographiclib INTERFACE "${PDNAV_GEOGRAPHICLIB_LIBRARY}")
  else()
    FetchContent_Declare(geographiclib
      GIT_REPOSITORY https://github.com/geographiclib/geographiclib.git
      GIT_TAG v2.1.2  # same version as Debian bookworm's libgeographiclib-dev
      GIT_SHALLOW TRUE)
    FetchContent_GetProperties(geographiclib)
    if(NOT geographiclib_POPULATED)
      FetchContent_Populate(geographiclib)
    endif()
    # static, no tools/docs in the default build (EXCLUDE_FROM_ALL: only what the core links)
    set(BUILD_SHARED_LIBS OFF)
    set(BUILD_BOTH_LIBS OFF)
    set(BUILD_DOCUMENTATION OFF)
    set(BUILD_MANPAGES OFF)
    add_subdirectory("${geographiclib_SOURCE_DIR}" "${geographiclib_BINARY_DIR}" EXCLUDE_FROM_ALL)
    set_target_properties(GeographicLib_STATIC PROPERTIES POSITION_INDEPENDENT_CODE ON)
    target_link_libraries(pdnav_geographiclib INTERFACE GeographicLib::GeographicLib_STATIC)
  endif()
endif()
