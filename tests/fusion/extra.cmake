# fusion CLI checks (issue 28): `pdnav eval-outage` on a simulated phone session (real DEM,
# walkway graph and broadcast ephemeris; fixtures from the terrain and route folders).
add_test(NAME fusion.eval_outage_session
  COMMAND /usr/bin/python3 "${CMAKE_CURRENT_SOURCE_DIR}/fusion/check_eval_outage.py" "$<TARGET_FILE:pdnav>"
          "${PROJECT_BINARY_DIR}/test-scratch/terrain-cli/andorra_30m.pdem"
          "${PROJECT_BINARY_DIR}/test-scratch/route-graph/andorra.graph"
          "${PDNAV_SHARED_DATA_DIR}/gnss-gsdc2021-pixel5/hour1180.21n"
          "${PROJECT_BINARY_DIR}/test-scratch/fusion-cli/eval-outage")
set_tests_properties(fusion.eval_outage_session PROPERTIES FIXTURES_REQUIRED "terrain_tile_andorra;route_andorra_graph"
                     LABELS "fusion;cli" TIMEOUT 600)

# Issue 28, compass deviation: tools/compass-deviation recovers a known one-cycle deviation
# (hard iron) from a synthetic Sensor Logger walk and rejects bad input (check_compass_deviation.py);
# on the real ETH walk the phone's compass error is one cycle (residual RMS <= 10 deg, a constant
# leaves >= 18 deg: measured 8.9 / 21.5) while the PDR's heading, with its gyro-aided hard-iron
# calibration active from 192 s, is within 12 deg RMS over the whole walk even as a constant
# (measured 10.0 on 2026-12-07; 14.8 with the sphere fit alone, active from 432 s; docs/pdr.md).
add_test(NAME fusion.compass_deviation_synthetic
  COMMAND /usr/bin/python3 "${CMAKE_CURRENT_SOURCE_DIR}/fusion/check_compass_deviation.py"
          "${PROJECT_SOURCE_DIR}/tools/compass-deviation" "${PROJECT_BINARY_DIR}/test-scratch/fusion-cli/compass-deviation")
set_tests_properties(fusion.compass_deviation_synthetic PROPERTIES LABELS "fusion;cli" TIMEOUT 60
                     PASS_REGULAR_EXPRESSION "compass-deviation checks passed")
set(_fusion_eth "${PDNAV_SHARED_DATA_DIR}/walk-ethz-sensorlogger/2023-03-17_15-50-47")
set(_fusion_dev_out "${PROJECT_BINARY_DIR}/test-scratch/fusion-cli/compass-deviation-eth")
add_test(NAME fusion.compass_deviation_eth
  COMMAND sh -c "\"$0\" replay \"$1\" --engine dr --mount auto --out \"$2\" >/dev/null && \
/usr/bin/python3 \"$3\" \"$1\" --dr \"$2\" --split-s 200 --out \"$2/deviation.png\""
          "$<TARGET_FILE:pdnav>" "${_fusion_eth}" "${_fusion_dev_out}" "${PROJECT_SOURCE_DIR}/tools/compass-deviation")
set_tests_properties(fusion.compass_deviation_eth PROPERTIES LABELS "fusion;cli" TIMEOUT 120
                     PASS_REGULAR_EXPRESSION "deviation: compass_pieces=4[0-9] compass_octants=[78] compass_rms_A_deg=(1[89]|2[0-9])\\.[0-9]+ compass_rms_ABC_deg=[0-9]\\.[0-9]+ .* pdr_pieces=4[0-9] pdr_octants=[78] pdr_rms_A_deg=([0-9]|1[01])\\.[0-9]+ pdr_rms_ABC_deg=([0-9]|1[01])\\.[0-9]+ .* pdr_after_pieces=[34][0-9] pdr_after_octants=[5-8] pdr_after_rms_A_deg=([0-9]|1[01])\\.[0-9]+ ")

# `pdnav replay`'s engines.csv: every running engine's own estimate once a second with its error
# against the truth (which engine said what when the fused estimate moved; check_engines_csv.py).
add_test(NAME fusion.replay_engines_csv
  COMMAND /usr/bin/python3 "${CMAKE_CURRENT_SOURCE_DIR}/fusion/check_engines_csv.py" "$<TARGET_FILE:pdnav>"
          "${PROJECT_BINARY_DIR}/test-scratch/terrain-cli/andorra_30m.pdem"
          "${PROJECT_BINARY_DIR}/test-scratch/route-graph/andorra.graph"
          "${PDNAV_SHARED_DATA_DIR}/gnss-gsdc2021-pixel5/hour1180.21n"
          "${PROJECT_BINARY_DIR}/test-scratch/fusion-cli/engines-csv")
set_tests_properties(fusion.replay_engines_csv PROPERTIES FIXTURES_REQUIRED "terrain_tile_andorra;route_andorra_graph"
                     LABELS "fusion;cli" TIMEOUT 300 PASS_REGULAR_EXPRESSION "engines.csv checks passed")
