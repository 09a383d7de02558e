// A file a CLI command writes (a session log, a converted recording): never one of the
// command's inputs, and never half-written. The data goes to NAME.partial, which commit()
// renames to NAME; a run that fails (bad input, full disk, an exception) removes the partial
// file and leaves whatever NAME was before untouched. ("Recorded sessions are never lost or
// truncated": `pdnav import x.log -o x.log` used to truncate x.log and then fail on it.)
#pragma once
#include <string>
#include <vector>

namespace pdnav::cli {

/// Throws std::invalid_argument "<option>PATH is the input INPUT: <advice>" when path names an
/// existing file that is one of inputs (the same file under any name: std::filesystem::equivalent).
void refuse_writing_over_input(const std::string& path, const std::vector<std::string>& inputs,
                               const std::string& option, const std::string& advice);

class OutputFile {
 public:
  /// refuse_writing_over_input first.
  OutputFile(std::string path, const std::vector<std::string>& inputs);
  OutputFile(const OutputFile&) = delete;
  OutputFile& operator=(const OutputFile&) = delete;
  ~OutputFile();
  /// Where to write until commit().
  const std::string& partial_path() const { return partial_; }
  const std::string& path() const { return path_; }
  /// The written partial file becomes path (an atomic rename on one file system).
  void commit();

 private:
  std::string path_, partial_;
  bool committed_ = false;
};

}  // namespace pdnav::cli
