# Simulator checks (issues 14 and 17). test_sim also covers the phone-session simulator.
target_link_libraries(test_sim PRIVATE pdnav::phonesim pdnav::gnss pdnav::route pdnav::terrain)
target_include_directories(test_sim PRIVATE "${CMAKE_CURRENT_SOURCE_DIR}/terrain")

set(_sim_tile "${PROJECT_BINARY_DIR}/test-scratch/terrain-cli/andorra_30m.pdem")   # terrain.make_andorra_tile
set(_sim_graph "${PROJECT_BINARY_DIR}/test-scratch/route-graph/andorra.graph")     # route_graph_andorra
set(_sim_nav "${PDNAV_SHARED_DATA_DIR}/gnss-gsdc2021-pixel5/hour1180.21n")
set(_sim_scratch "${PROJECT_BINARY_DIR}/test-scratch/sim-cli")

# A whole phone session on the real DEM and walkway graph with real broadcast ephemeris:
# reproducible, every line type, no GNSS in the outage, `pdnav gnss` near the truth, replays.
add_test(NAME sim.session_log
  COMMAND /usr/bin/python3 "${CMAKE_CURRENT_SOURCE_DIR}/sim/check_session.py" "$<TARGET_FILE:pdnav>"
          "${_sim_tile}" "${_sim_graph}" "${_sim_nav}" "${_sim_scratch}/session")
set_tests_properties(sim.session_log PROPERTIES FIXTURES_REQUIRED "terrain_tile_andorra;route_andorra_graph"
                     LABELS "sim;cli" TIMEOUT 300)

# eval-fusion on a few short walks: it runs, prints the table, and its figures are sane.
add_test(NAME sim.eval_fusion_short
  COMMAND /usr/bin/python3 "${CMAKE_CURRENT_SOURCE_DIR}/sim/check_eval_fusion.py" --
          "$<TARGET_FILE:pdnav>" eval-fusion --dem "${_sim_tile}" --graph "${_sim_graph}" --nav "${_sim_nav}"
          --walks 3 --seed 2 --outage-min 2 --outage-max 3 --lead 200 --tail 90)
set_tests_properties(sim.eval_fusion_short PROPERTIES FIXTURES_REQUIRED "terrain_tile_andorra;route_andorra_graph"
                     LABELS "sim;cli" TIMEOUT 600)

# Clear errors: a missing navigation file, and a tile without the graph in it.
add_test(NAME sim.eval_fusion_missing_nav
  COMMAND "$<TARGET_FILE:pdnav>" eval-fusion --dem "${_sim_tile}" --graph "${_sim_graph}" --nav "${PROJECT_BINARY_DIR}/no-such.21n")
set_tests_properties(sim.eval_fusion_missing_nav PROPERTIES FIXTURES_REQUIRED "terrain_tile_andorra;route_andorra_graph"
                     LABELS "sim;cli" PASS_REGULAR_EXPRESSION "no-such.21n")
