# Terrain CLI checks (issue 5 bar). The DEM tile is made from the real SRTM tile by dem-tools
# in a fixture setup step; eval-terrain then runs 20 simulated walks with 500 particles.
set(PDNAV_TERRAIN_SCRATCH "${PROJECT_BINARY_DIR}/test-scratch/terrain-cli")
set(PDNAV_TERRAIN_TILE "${PDNAV_TERRAIN_SCRATCH}/andorra_30m.pdem")
add_test(NAME terrain.make_andorra_tile
  COMMAND ${CMAKE_COMMAND} -E env /usr/bin/python3 "${PROJECT_SOURCE_DIR}/dem-tools/pdnav_dem.py" tile
          "/vsizip/${PDNAV_SHARED_DATA_DIR}/terrain-andorra/N42E001.hgt.zip/N42E001.hgt"
          -o "${PDNAV_TERRAIN_TILE}" --center 42.55 1.55 --radius 12000 --cell 30 --fill-voids)
set_tests_properties(terrain.make_andorra_tile PROPERTIES FIXTURES_SETUP terrain_tile LABELS "terrain;dem-tools")
file(MAKE_DIRECTORY "${PDNAV_TERRAIN_SCRATCH}")

add_test(NAME terrain.eval_bar
  COMMAND /usr/bin/python3 "${CMAKE_CURRENT_SOURCE_DIR}/terrain/check_eval_bar.py"
          "$<TARGET_FILE:pdnav>" "${PDNAV_TERRAIN_TILE}")
set_tests_properties(terrain.eval_bar PROPERTIES FIXTURES_REQUIRED terrain_tile LABELS "terrain;cli" TIMEOUT 300)

add_test(NAME terrain.simulate_log
  COMMAND /usr/bin/python3 "${CMAKE_CURRENT_SOURCE_DIR}/terrain/check_simulate.py"
          "$<TARGET_FILE:pdnav>" "${PDNAV_TERRAIN_TILE}" "${PDNAV_TERRAIN_SCRATCH}")
set_tests_properties(terrain.simulate_log PROPERTIES FIXTURES_REQUIRED terrain_tile LABELS "terrain;cli" TIMEOUT 120)

# Generalisation: the same bar on a second area of the SRTM tile, 40 km west-north-west of the
# first (Pallars Sobira, 414-2767 m), with no parameter changed.
set(PDNAV_TERRAIN_TILE_WEST "${PDNAV_TERRAIN_SCRATCH}/pallars_30m.pdem")
add_test(NAME terrain.make_pallars_tile
  COMMAND ${CMAKE_COMMAND} -E env /usr/bin/python3 "${PROJECT_SOURCE_DIR}/dem-tools/pdnav_dem.py" tile
          "/vsizip/${PDNAV_SHARED_DATA_DIR}/terrain-andorra/N42E001.hgt.zip/N42E001.hgt"
          -o "${PDNAV_TERRAIN_TILE_WEST}" --center 42.85 1.15 --radius 12000 --cell 30 --fill-voids)
set_tests_properties(terrain.make_pallars_tile PROPERTIES FIXTURES_SETUP terrain_tile_west LABELS "terrain;dem-tools")
add_test(NAME terrain.eval_bar_other_area
  COMMAND /usr/bin/python3 "${CMAKE_CURRENT_SOURCE_DIR}/terrain/check_eval_bar.py"
          "$<TARGET_FILE:pdnav>" "${PDNAV_TERRAIN_TILE_WEST}")
set_tests_properties(terrain.eval_bar_other_area PROPERTIES FIXTURES_REQUIRED terrain_tile_west LABELS "terrain;cli" TIMEOUT 300)
