// The readers behind io::open_sample_source (docs/log-format.md, "Other loggers").
#pragma once
#include <memory>
#include <string>

#include "io/container.h"
#include "pdnav/io/sample_source.h"

namespace pdnav::io::detail {

/// What a container looks like: which format's files it holds (kAuto = none recognised).
/// `found` describes what it holds, for the error message.
Format sniff_container(const Container& c, std::string& found);

std::unique_ptr<SampleSource> open_sensorlogger(std::unique_ptr<Container> c, SourceOptions opt);
std::unique_ptr<SampleSource> open_phyphox(std::unique_ptr<Container> c, SourceOptions opt);
/// GetSensorData text log from a stream; `size` for progress (0 = unknown).
std::unique_ptr<SampleSource> open_getsensordata(std::unique_ptr<std::istream> in, std::string name,
                                                 std::uint64_t size, SourceOptions opt);

/// The first header of a Sensor Logger CSV ("time,seconds_elapsed,...").
bool is_sensorlogger_header(const std::string& line);
/// The first header of a phyphox CSV ("Time (s)",...).
bool is_phyphox_header(const std::string& line);

}  // namespace pdnav::io::detail
