#include "support/output_file.h"

#include <filesystem>
#include <stdexcept>
#include <system_error>
#include <utility>

namespace pdnav::cli {

OutputFile::OutputFile(std::string path, const std::vector<std::string>& inputs)
    : path_(std::move(path)), partial_(path_ + ".partial") {
  std::error_code ec;
  if (std::filesystem::exists(path_, ec))
    for (const std::string& input : inputs)
      if (std::filesystem::equivalent(path_, input, ec))
        throw std::invalid_argument(path_ + " is the input " + input + ": choose another output file");
}

OutputFile::~OutputFile() {
  if (committed_) return;
  std::error_code ec;
  std::filesystem::remove(partial_, ec);  // a failed run leaves no half-written file
}

void OutputFile::commit() {
  std::filesystem::rename(partial_, path_);  // throws filesystem_error with both paths
  committed_ = true;
}

}  // namespace pdnav::cli
