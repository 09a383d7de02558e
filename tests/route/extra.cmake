# route: the issue-6 bar on real OpenStreetMap streets. The fixture builds the Andorra
# walkway graph with dem-tools (GDAL, /usr/bin/python3); the eval asserts the bar by parsing
# the last lines of `pdnav eval-route` (tests/route/check_eval_route.py).
set(_route_graph "${PROJECT_BINARY_DIR}/test-scratch/route-graph/andorra.graph")
set(_route_osm "${PDNAV_SHARED_DATA_DIR}/terrain-andorra/andorra.osm.pbf")

add_test(NAME route_graph_andorra
         COMMAND /usr/bin/python3 "${PROJECT_SOURCE_DIR}/dem-tools/pdnav_graph.py" "${_route_osm}" "${_route_graph}")
set_tests_properties(route_graph_andorra PROPERTIES LABELS "route;dem-tools" FIXTURES_SETUP route_andorra_graph
                     PASS_REGULAR_EXPRESSION "[0-9]+ ways -> [0-9]+ vertices, [0-9]+ edges")

add_test(NAME route_eval_andorra
         COMMAND /usr/bin/python3 "${CMAKE_CURRENT_LIST_DIR}/check_eval_route.py"
                 --max-median-turn 3 --max-p95-turn 10 --min-gnss-ratio 2 --
                 "$<TARGET_FILE:pdnav>" eval-route --graph "${_route_graph}" --walks 200 --seed 1)
set_tests_properties(route_eval_andorra PROPERTIES LABELS "route;cli" FIXTURES_REQUIRED route_andorra_graph)

# The --osm path: the command builds (and caches) the graph itself.
add_test(NAME route_eval_osm_cached
         COMMAND "$<TARGET_FILE:pdnav>" eval-route --osm "${_route_osm}" --walks 3 --seed 5
                 --cache-dir "${PROJECT_BINARY_DIR}/test-scratch/route-cache")
set_tests_properties(route_eval_osm_cached PROPERTIES LABELS "route;cli"
  PASS_REGULAR_EXPRESSION "walks: 3 .*median_turn_error_m: [0-9.]+ p95_turn_error_m: [0-9.]+ gnss_median_error_m: [0-9.]+\n$")

add_test(NAME route_eval_missing_graph
         COMMAND "$<TARGET_FILE:pdnav>" eval-route --graph "${PROJECT_BINARY_DIR}/no-such.graph")
set_tests_properties(route_eval_missing_graph PROPERTIES LABELS "route;cli" WILL_FAIL TRUE)

# issue 29: `pdnav route` (route::Router, A*) against an independent scipy Dijkstra on the same
# Andorra graph: 60 fixed-seed query pairs, lengths and snaps equal within 0.1 m, no-path agreed.
add_test(NAME route_shortest_vs_scipy
         COMMAND /usr/bin/python3 "${CMAKE_CURRENT_LIST_DIR}/check_shortest_path.py"
                 --pdnav "$<TARGET_FILE:pdnav>" --graph "${_route_graph}" --pairs 60 --seed 1 --tol 0.1)
set_tests_properties(route_shortest_vs_scipy PROPERTIES LABELS "route;cli" FIXTURES_REQUIRED route_andorra_graph
                     TIMEOUT 300)
add_test(NAME route_cli_bad_point
         COMMAND "$<TARGET_FILE:pdnav>" route --graph "${_route_graph}" --from 42.5,nan --to 42.5,1.5)
set_tests_properties(route_cli_bad_point PROPERTIES LABELS "route;cli" FIXTURES_REQUIRED route_andorra_graph
                     PASS_REGULAR_EXPRESSION "--from: expected LAT,LON in degrees")
add_test(NAME route_cli_missing_graph
         COMMAND "$<TARGET_FILE:pdnav>" route --graph "${PROJECT_BINARY_DIR}/no-such.graph" --from 42.5,1.5 --to 42.5,1.5)
set_tests_properties(route_cli_missing_graph PROPERTIES LABELS "route;cli" WILL_FAIL TRUE)
