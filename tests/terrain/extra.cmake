# Terrain CLI checks (issue 5 bar). Each area's DEM tile is made from the real SRTM tile by
# dem-tools in a fixture setup step; eval-terrain then runs 20 simulated walks with 500
# particles on it and check_eval_bar.py checks the bar on its last line.
set(PDNAV_TERRAIN_SCRATCH "${PROJECT_BINARY_DIR}/test-scratch/terrain-cli")
set(PDNAV_TERRAIN_TILE "${PDNAV_TERRAIN_SCRATCH}/andorra_30m.pdem")
file(MAKE_DIRECTORY "${PDNAV_TERRAIN_SCRATCH}")

# pdnav_terrain_area(NAME LAT LON TEST): tile `<NAME>_30m.pdem` (24 x 24 km around LAT LON,
# 30 m cells, voids filled) made by test `terrain.make_<NAME>_tile`, and the bar test TEST on it.
function(pdnav_terrain_area name lat lon test)
  set(eval_args ${ARGN})
  set(tile "${PDNAV_TERRAIN_SCRATCH}/${name}_30m.pdem")
  add_test(NAME terrain.make_${name}_tile
    COMMAND ${CMAKE_COMMAND} -E env /usr/bin/python3 "${PROJECT_SOURCE_DIR}/dem-tools/pdnav_dem.py" tile
            "/vsizip/${PDNAV_SHARED_DATA_DIR}/terrain-andorra/N42E001.hgt.zip/N42E001.hgt"
            -o "${tile}" --center ${lat} ${lon} --radius 12000 --cell 30 --fill-voids)
  set_tests_properties(terrain.make_${name}_tile PROPERTIES FIXTURES_SETUP terrain_tile_${name}
                       LABELS "terrain;dem-tools")
  add_test(NAME ${test}
    COMMAND /usr/bin/python3 "${CMAKE_CURRENT_SOURCE_DIR}/terrain/check_eval_bar.py" "$<TARGET_FILE:pdnav>" "${tile}"
            ${eval_args})
  set_tests_properties(${test} PROPERTIES FIXTURES_REQUIRED terrain_tile_${name} LABELS "terrain;cli" TIMEOUT 300)
endfunction()

pdnav_terrain_area(andorra 42.55 1.55 terrain.eval_bar --path direct)
# Generalisation: the same bar, no parameter changed, on a second area 40 km west-north-west
# (Pallars Sobira, 414-2767 m).
pdnav_terrain_area(pallars 42.85 1.15 terrain.eval_bar_other_area --path direct)
# Issue 17: the app's path (session log writer, reader, PDR, Navigator, as `pdnav replay`) with
# the per-area bar (median ratio <= 0.45, 68 % coverage 0.60-0.80) under the world error models,
# on the area's figure as tools/terrain-areas defines it (mean over seeds 1,2,3); the full bar
# over 6 areas x 3 seeds is tools/terrain-areas (docs/terrain.md).
add_test(NAME terrain.eval_bar_app_path
  COMMAND /usr/bin/python3 "${CMAKE_CURRENT_SOURCE_DIR}/terrain/check_eval_bar.py" "$<TARGET_FILE:pdnav>"
          "${PDNAV_TERRAIN_TILE}" --bar 0.45,0.60,0.80 --seeds 1,2,3 --path app --tmp-dir "${PDNAV_TERRAIN_SCRATCH}")
set_tests_properties(terrain.eval_bar_app_path PROPERTIES FIXTURES_REQUIRED terrain_tile_andorra
                     LABELS "terrain;cli" TIMEOUT 300)

# Issue 28: over 12 whole simulated walks without GNSS (app path: replay dr / terrain / auto) the
# pooled fused estimate is inside its 1-sigma ellipse 30-50 % of the time and the terrain estimate
# inside its 68 % region 60-80 % (tools/whole-walks --check).
add_test(NAME terrain.whole_walks_coverage
  COMMAND /usr/bin/python3 "${PROJECT_SOURCE_DIR}/tools/whole-walks" --dem "${PDNAV_TERRAIN_TILE}"
          --pdnav "$<TARGET_FILE:pdnav>" --seeds 1-12 --out "${PDNAV_TERRAIN_SCRATCH}/whole-walks" --check)
set_tests_properties(terrain.whole_walks_coverage PROPERTIES FIXTURES_REQUIRED terrain_tile_andorra
                     LABELS "terrain;cli" TIMEOUT 300)

add_test(NAME terrain.simulate_log
  COMMAND /usr/bin/python3 "${CMAKE_CURRENT_SOURCE_DIR}/terrain/check_simulate.py"
          "$<TARGET_FILE:pdnav>" "${PDNAV_TERRAIN_TILE}" "${PDNAV_TERRAIN_SCRATCH}")
set_tests_properties(terrain.simulate_log PROPERTIES FIXTURES_REQUIRED terrain_tile_andorra LABELS "terrain;cli" TIMEOUT 120)

# A tile too small for any route (1 km across, 800 m edge margin): every walk is reported as
# skipped with its reason and the command ends with a clear error, not a crash.
set(PDNAV_TERRAIN_TINY "${PDNAV_TERRAIN_SCRATCH}/tiny_30m.pdem")
add_test(NAME terrain.make_tiny_tile
  COMMAND ${CMAKE_COMMAND} -E env /usr/bin/python3 "${PROJECT_SOURCE_DIR}/dem-tools/pdnav_dem.py" tile
          "/vsizip/${PDNAV_SHARED_DATA_DIR}/terrain-andorra/N42E001.hgt.zip/N42E001.hgt"
          -o "${PDNAV_TERRAIN_TINY}" --center 42.55 1.55 --radius 500 --cell 30 --fill-voids)
set_tests_properties(terrain.make_tiny_tile PROPERTIES FIXTURES_SETUP terrain_tile_tiny LABELS "terrain;dem-tools")
add_test(NAME terrain.eval_tile_too_small
  COMMAND pdnav eval-terrain --dem "${PDNAV_TERRAIN_TINY}" --walks 2 --seed 1)
set_tests_properties(terrain.eval_tile_too_small PROPERTIES FIXTURES_REQUIRED terrain_tile_tiny LABELS "terrain;cli"
  PASS_REGULAR_EXPRESSION "skipped: simulate: DEM tile too small for the edge margin.*only 0 of 2 walks fit the tile after 6 seeds"
  TIMEOUT 60)

# The DR error breakdown whole-walks and the demo print (tools/track_breakdown.py): the oracle
# rebuilds remove exactly the error source they know about on synthetic tracks.
add_test(NAME terrain.track_breakdown
  COMMAND /usr/bin/python3 "${CMAKE_CURRENT_SOURCE_DIR}/terrain/check_track_breakdown.py")
set_tests_properties(terrain.track_breakdown PROPERTIES LABELS "terrain;tools" TIMEOUT 60)
