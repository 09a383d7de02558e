# ---- terrain helper: DEM tiler + basemap tests (begin) ----
add_test(NAME dem_tools.pdnav_dem
  COMMAND /usr/bin/python3 "${CMAKE_CURRENT_SOURCE_DIR}/dem-tools/test_pdnav_dem.py"
          "${PDNAV_SHARED_DATA_DIR}" "${PROJECT_BINARY_DIR}/test-scratch/dem-tools-pdem")
set_tests_properties(dem_tools.pdnav_dem PROPERTIES LABELS "dem-tools" TIMEOUT 300)
# ---- terrain helper: DEM tiler + basemap tests (end) ----
include(${CMAKE_CURRENT_LIST_DIR}/graph.cmake)
# ---- basemap: Mapnik renderer tests (dem-tools/pdnav_basemap.py), issue 21 (begin) ----
add_test(NAME dem_tools.basemap
  COMMAND /usr/bin/python3 "${CMAKE_CURRENT_SOURCE_DIR}/dem-tools/test_basemap.py"
          "${PDNAV_SHARED_DATA_DIR}" "${PROJECT_BINARY_DIR}/test-scratch/dem-tools-basemap")
set_tests_properties(dem_tools.basemap PROPERTIES LABELS "dem-tools" TIMEOUT 600)
# ---- basemap (end) ----
# ---- region pack (dem-tools/pdnav_region.py), issue 29 (begin) ----
add_test(NAME dem_tools.region
  COMMAND /usr/bin/python3 "${CMAKE_CURRENT_SOURCE_DIR}/dem-tools/test_region.py"
          "${PDNAV_SHARED_DATA_DIR}" "${PROJECT_BINARY_DIR}/test-scratch/dem-tools-region" "$<TARGET_FILE:pdnav>")
set_tests_properties(dem_tools.region PROPERTIES LABELS "dem-tools" TIMEOUT 300)
# ---- region pack (end) ----
