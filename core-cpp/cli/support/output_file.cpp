#include "support/output_file.h"

#include <filesystem>
#include <stdexcept>
#include <system_error>
#include <utility>

namespace pdnav::cli {

void refuse_writing_over_input(const std::string& path, const std::vector<std::string>& inputs,
                               const std::string& option, const std::string& advice) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) return;
  for (const std::string& input : inputs)
    if (std::filesystem::equivalent(path, input, ec))
      throw std::invalid_argument(option + path + " is the input " + input + ": " + advice);
}

OutputFile::OutputFile(std::string path, const std::vector<std::string>& inputs)
    : path_(std::move(path)), partial_(path_ + ".partial") {
  refuse_writing_over_input(path_, inputs, "", "choose another output file");
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
