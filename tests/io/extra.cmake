# `pdnav inspect` on the real logs and the excerpts (label io). Included by tests/CMakeLists.txt.
set(_io_mv "${PDNAV_SHARED_DATA_DIR}/gnss-mountainview/pseudoranges_log_2016_08_22_14_45_50.txt")
set(_io_p7 "${PDNAV_SHARED_DATA_DIR}/gnss-pixel7-format/gnsslogger_v3_pixel7.txt")

add_test(NAME io_inspect_mountainview COMMAND pdnav inspect "${_io_mv}")
set_tests_properties(io_inspect_mountainview PROPERTIES LABELS "io;cli"
  PASS_REGULAR_EXPRESSION "Version=1.4.0.0.*Fix +206 .*Raw +5041 .*no elapsed-time base yet: 1.*:12: no elapsed-time base yet.*samples: 5247 skipped: 1\n")

add_test(NAME io_inspect_pixel7 COMMAND pdnav inspect "${_io_p7}")
set_tests_properties(io_inspect_pixel7 PROPERTIES LABELS "io;cli"
  PASS_REGULAR_EXPRESSION "Model=Pixel 7.*Agc +80 .*Fix +243 .*Raw +930 +31 .*samples: 1293 skipped: 0\n")

add_test(NAME io_inspect_excerpt COMMAND pdnav inspect "${CMAKE_CURRENT_SOURCE_DIR}/data/logs/mountainview_v1_4_excerpt.txt")
set_tests_properties(io_inspect_excerpt PROPERTIES LABELS "io;cli"
  PASS_REGULAR_EXPRESSION "samples: 70 skipped: 1\n")

add_test(NAME io_inspect_missing_file COMMAND pdnav inspect "${CMAKE_CURRENT_BINARY_DIR}/no-such-log.txt")
set_tests_properties(io_inspect_missing_file PROPERTIES LABELS "io;cli" WILL_FAIL TRUE)

# pdnav's own line types GameRotationVector and SensorAccuracy are counted like any other
# (the fuzz seed: 2 + 4 good lines, one accuracy 7 and one short quaternion skipped)
add_test(NAME io_inspect_game_rotation_and_accuracy
         COMMAND pdnav inspect "${PROJECT_SOURCE_DIR}/tests/fuzz-corpus/log_reader/game_rotation_and_accuracy.txt")
set_tests_properties(io_inspect_game_rotation_and_accuracy PROPERTIES LABELS "io;cli"
  PASS_REGULAR_EXPRESSION "GameRotationVector +2 .*SensorAccuracy +4 .*value out of range: 1.*wrong field count: 1.*samples: 8 skipped: 2\n")
