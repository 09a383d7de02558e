// Paths to test data. Shared real data lives in ../shared/data beside the project root;
// a missing file fails the test loudly with the path it looked for (never a silent skip).
#pragma once
#include <filesystem>
#include <string>

#include <gtest/gtest.h>

namespace pdnav::test {

inline std::string shared_data(const std::string& rel) {
  const std::filesystem::path p = std::filesystem::path(PDNAV_SHARED_DATA_DIR) / rel;
  if (!std::filesystem::exists(p)) {
    ADD_FAILURE() << "shared data missing: " << p
                  << " (put ../shared beside the project root or set -DPDNAV_SHARED_DATA_DIR)";
  }
  return p.string();
}

inline std::string test_data(const std::string& rel) {
  const std::filesystem::path p = std::filesystem::path(PDNAV_TEST_DATA_DIR) / rel;
  if (!std::filesystem::exists(p)) ADD_FAILURE() << "test data missing: " << p;
  return p.string();
}

/// A fresh, empty scratch directory under the build tree for one test.
inline std::filesystem::path scratch_dir(const std::string& name) {
  const auto p = std::filesystem::path(PDNAV_BINARY_DIR) / "test-scratch" / name;
  std::filesystem::remove_all(p);
  std::filesystem::create_directories(p);
  return p;
}

inline std::string pdnav_cli() { return (std::filesystem::path(PDNAV_BINARY_DIR) / "pdnav").string(); }

}  // namespace pdnav::test
