// Reader for the Oxford Step Counter data set's CSV layout (github.com/Oxford-step-counter/DataSet,
// CC BY 4.0): no header, `timestamp_ns_since_boot, accx, accy, accz, steps_algo,
// steps_groundtruth, steps_hw_counter` (counts cumulative). Header-only so the pdr tests can
// use the same reader as `pdnav steps --format oxford`.
#pragma once
#include <cctype>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "pdnav/geo/samples.h"

namespace pdnav::cli {

struct OxfordRecording {
  std::string path;
  std::vector<AccelSample> samples;
  std::int64_t truth_steps = 0;      // last value of column 6
  std::int64_t algo_steps = 0;       // last value of column 5 (the data set's own algorithm)
  std::int64_t hw_steps = 0;         // last value of column 7 (0 when not recorded)
  std::int64_t skipped_lines = 0;    // malformed lines (counted, first reported in first_issue)
  std::string first_issue;           // "file:line: reason" of the first skipped line
};

/// Parses one CSV line into 7 numbers; false when the line is malformed.
inline bool parse_oxford_line(const std::string& line, double (&v)[7], std::int64_t& t_ns) {
  std::istringstream ls(line);
  std::string tok;
  int i = 0;
  while (std::getline(ls, tok, ',')) {
    if (i >= 7) return false;
    try {
      std::size_t used = 0;
      if (i == 0) {
        t_ns = std::stoll(tok, &used);
        v[0] = 0.0;
      } else {
        v[i] = std::stod(tok, &used);
      }
      while (used < tok.size() && std::isspace(static_cast<unsigned char>(tok[used]))) ++used;
      if (used != tok.size()) return false;
    } catch (const std::exception&) {
      return false;
    }
    ++i;
  }
  return i == 7;
}

/// Reads a whole recording. An all-zero first row (the data set's start marker) is dropped.
/// Throws std::runtime_error("path:0: cannot open") when the file cannot be read.
inline OxfordRecording read_oxford_csv(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ":0: cannot open Oxford CSV");
  OxfordRecording rec;
  rec.path = path;
  std::string line;
  std::int64_t line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty()) continue;
    double v[7] = {};
    std::int64_t t_ns = 0;
    if (!parse_oxford_line(line, v, t_ns)) {
      if (rec.skipped_lines++ == 0) rec.first_issue = path + ":" + std::to_string(line_no) + ": malformed line";
      continue;
    }
    rec.algo_steps = static_cast<std::int64_t>(v[4]);
    rec.truth_steps = static_cast<std::int64_t>(v[5]);
    rec.hw_steps = static_cast<std::int64_t>(v[6]);
    if (v[1] == 0.0 && v[2] == 0.0 && v[3] == 0.0) continue;  // start marker / sensor not ready
    AccelSample s;
    s.t_ns = t_ns;
    s.acc_mps2 = Eigen::Vector3d(v[1], v[2], v[3]);
    rec.samples.push_back(s);  // NaN values are kept: the detector counts and skips them
  }
  return rec;
}

}  // namespace pdnav::cli
