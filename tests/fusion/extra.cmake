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
