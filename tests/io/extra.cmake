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

# Other loggers (docs/log-format.md "Other loggers"): the shared Sensor Logger walk (folder,
# and a zip made from it at test time with `cmake -E tar --format=zip`), the phyphox and
# GetSensorData fixtures written from their specs; wrong input is an error.
set(_io_walk "${PDNAV_SHARED_DATA_DIR}/walk-ethz-sensorlogger/2023-03-17_15-50-47")
add_test(NAME io_inspect_sensorlogger_folder COMMAND pdnav inspect "${_io_walk}")
set_tests_properties(io_inspect_sensorlogger_folder PROPERTIES LABELS "io;cli"
  PASS_REGULAR_EXPRESSION "\\(sensorlogger\\).*Accel +34667 .*Fix +1091 .*Gyro +34648 .*Pressure +3853 .*not used: [^\n]*Gravity.csv.*samples: 178209 skipped: 0\n")
add_test(NAME io_sensorlogger_zip_make
         COMMAND "${CMAKE_COMMAND}" -E chdir "${PDNAV_SHARED_DATA_DIR}/walk-ethz-sensorlogger"
                 "${CMAKE_COMMAND}" -E tar cf "${CMAKE_CURRENT_BINARY_DIR}/ethz-walk.zip" --format=zip 2023-03-17_15-50-47)
set_tests_properties(io_sensorlogger_zip_make PROPERTIES LABELS "io;cli" FIXTURES_SETUP io_sl_zip)
add_test(NAME io_inspect_sensorlogger_zip COMMAND pdnav inspect "${CMAKE_CURRENT_BINARY_DIR}/ethz-walk.zip")
set_tests_properties(io_inspect_sensorlogger_zip PROPERTIES LABELS "io;cli" FIXTURES_REQUIRED io_sl_zip
  PASS_REGULAR_EXPRESSION "sensorlogger\\).*Accel +34667 .*Fix +1091 .*samples: 178209 skipped: 0\n")
add_test(NAME io_replay_sensorlogger_zip
         COMMAND pdnav replay "${CMAKE_CURRENT_BINARY_DIR}/ethz-walk.zip" --out "${CMAKE_CURRENT_BINARY_DIR}/replay-ethz-zip" --quiet)
set_tests_properties(io_replay_sensorlogger_zip PROPERTIES LABELS "io;cli" FIXTURES_REQUIRED io_sl_zip
  PASS_REGULAR_EXPRESSION "\\(sensorlogger\\)\nsamples:  178209 \\(skipped lines: 0\\).*\npdr: +867 steps, [0-9.]+ m \\(accel\\+gyro\\+mag, heading: magnetometer\\). refused: handling 0, vehicle 0. vehicle spans: none. .*reference: gps-fix")
add_test(NAME io_inspect_phyphox_fixture COMMAND pdnav inspect "${PROJECT_SOURCE_DIR}/tests/data/loggers/phyphox-walk")
set_tests_properties(io_inspect_phyphox_fixture PROPERTIES LABELS "io;cli"
  PASS_REGULAR_EXPRESSION "\\(phyphox\\).*Accel +3000 .*Fix +30 .*Gyro +3000 .*Mag +1500 .*Pressure +150 .*samples: 7683 skipped: 0\n")
add_test(NAME io_inspect_getsensordata_fixture COMMAND pdnav inspect "${PROJECT_SOURCE_DIR}/tests/data/loggers/getsensordata-walk.txt")
set_tests_properties(io_inspect_getsensordata_fixture PROPERTIES LABELS "io;cli"
  PASS_REGULAR_EXPRESSION "getsensordata\\).*Accel +1500 .*Fix +30 .*RotationVector +300 .*Truth +4 .*line type 'LIGH' not used: 150.*samples: 5286 skipped: 180\n")
add_test(NAME io_replay_not_a_log COMMAND pdnav replay /etc/passwd --out "${CMAKE_CURRENT_BINARY_DIR}/replay-not-a-log")
set_tests_properties(io_replay_not_a_log PROPERTIES LABELS "io;cli" WILL_FAIL TRUE)
add_test(NAME io_replay_not_a_log_message COMMAND pdnav replay /etc/passwd --out "${CMAKE_CURRENT_BINARY_DIR}/replay-not-a-log")
set_tests_properties(io_replay_not_a_log_message PROPERTIES LABELS "io;cli"
  PASS_REGULAR_EXPRESSION "not a recording pdnav reads: expected .*. found first line")
# a RINEX file given to replay says which command reads it (the shared GSDC observation file)
add_test(NAME io_replay_rinex_obs_message
         COMMAND pdnav replay "${PDNAV_SHARED_DATA_DIR}/gnss-gsdc2021-pixel5/Pixel5_first_half.21o" --out "${CMAKE_CURRENT_BINARY_DIR}/replay-rinex")
set_tests_properties(io_replay_rinex_obs_message PROPERTIES LABELS "io;cli"
  PASS_REGULAR_EXPRESSION "not a recording pdnav reads: .*a RINEX observation file: `pdnav gnss` reads it")
# the other shared files a field tester may pass by mistake say which command and option take
# them: an SP3 orbit file, a GSDC truth table, an Oxford step-counter CSV (exit non-zero each)
add_test(NAME io_replay_other_kinds_message
         COMMAND sh -c "for f in \"$1/gnss-orbits-2023-073/COD0OPSRAP_20230730000_01D_05M_ORB.SP3\" \"$1/gnss-gsdc2021-pixel5/ground_truth_first_half.csv\" \"$1/steps-oxford/user1_hand_1506421989895.csv\"; do \"$0\" replay \"$f\" --out \"$2\" --quiet 2>&1; echo \"rc=$?\"; done"
                 $<TARGET_FILE:pdnav> "${PDNAV_SHARED_DATA_DIR}" "${CMAKE_CURRENT_BINARY_DIR}/replay-other-kinds")
set_tests_properties(io_replay_other_kinds_message PROPERTIES LABELS "io;cli"
  PASS_REGULAR_EXPRESSION "an SP3 precise orbit file: `pdnav gnss` and `pdnav orbits` take it with --sp3.\nrc=1\n.*a GSDC ground-truth table: `pdnav gnss` takes it with --truth-csv.\nrc=1\n.*an Oxford step-counter CSV. `pdnav steps --format oxford` reads it.\nrc=1\n")
add_test(NAME io_inspect_one_sensorlogger_csv COMMAND pdnav inspect "${_io_walk}/Accelerometer.csv")
set_tests_properties(io_inspect_one_sensorlogger_csv PROPERTIES LABELS "io;cli" WILL_FAIL TRUE)

# `pdnav import` -> `pdnav replay` equals `pdnav replay` of the recording itself (track.csv
# compared byte for byte), on the phyphox and GetSensorData fixtures.
foreach(_fx phyphox-walk getsensordata-walk.txt)
  string(REGEX REPLACE "[^a-z]" "_" _n "${_fx}")
  set(_in "${PROJECT_SOURCE_DIR}/tests/data/loggers/${_fx}")
  set(_d "${CMAKE_CURRENT_BINARY_DIR}/import-${_n}")
  add_test(NAME io_import_${_n} COMMAND pdnav import "${_in}" -o "${_d}.log")
  set_tests_properties(io_import_${_n} PROPERTIES LABELS "io;cli" FIXTURES_SETUP io_imp_${_n}
    PASS_REGULAR_EXPRESSION "-> [^\n]*: [0-9]+ samples")
  add_test(NAME io_import_replay_direct_${_n} COMMAND pdnav replay "${_in}" --out "${_d}-direct" --quiet)
  add_test(NAME io_import_replay_imported_${_n} COMMAND pdnav replay "${_d}.log" --out "${_d}-imported" --quiet)
  set_tests_properties(io_import_replay_direct_${_n} io_import_replay_imported_${_n} PROPERTIES LABELS "io;cli"
    FIXTURES_REQUIRED io_imp_${_n} FIXTURES_SETUP io_imp_replayed_${_n})
  add_test(NAME io_import_replay_identical_${_n}
           COMMAND "${CMAKE_COMMAND}" -E compare_files "${_d}-direct/track.csv" "${_d}-imported/track.csv")
  set_tests_properties(io_import_replay_identical_${_n} PROPERTIES LABELS "io;cli" FIXTURES_REQUIRED io_imp_replayed_${_n})
endforeach()

# `pdnav import` never loses a recording: importing a log onto itself is refused (exit 1) and
# leaves it byte for byte; an import that fails after writing began (--strict and a malformed
# last line) leaves an existing output as it was and no NAME.partial behind.
add_test(NAME io_import_never_over_a_recording
         COMMAND sh -c "d=\"$2\"; rm -rf \"$d\"; mkdir -p \"$d\" || exit 1; \"$0\" import \"$1\" -o \"$d/x.log\" >/dev/null || exit 1; cp \"$d/x.log\" \"$d/copy.log\"; \"$0\" import \"$d/x.log\" -o \"$d/x.log\" >/dev/null 2>&1; echo rc=$?; cmp -s \"$d/x.log\" \"$d/copy.log\" && echo self-intact; cp \"$d/x.log\" \"$d/bad.log\" && echo 'Accel,1,2,x,y,z' >> \"$d/bad.log\"; \"$0\" import --strict \"$d/bad.log\" -o \"$d/copy.log\" >/dev/null 2>&1; echo rc=$?; cmp -s \"$d/x.log\" \"$d/copy.log\" && echo output-intact; ls \"$d\" | grep -c partial"
         $<TARGET_FILE:pdnav> "${PROJECT_SOURCE_DIR}/tests/data/loggers/getsensordata-walk.txt"
         "${CMAKE_CURRENT_BINARY_DIR}/import-never-over")
set_tests_properties(io_import_never_over_a_recording PROPERTIES LABELS "io;cli"
  PASS_REGULAR_EXPRESSION "rc=1\nself-intact\nrc=1\noutput-intact\n0\n")
