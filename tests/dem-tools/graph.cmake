# dem-tools walkway graph extraction (dem-tools/pdnav_graph.py) on a small OSM file the test
# writes: junction splitting, oneway ignored, foot=no / access=private excluded.
add_test(NAME dem_tools_graph_extraction
         COMMAND /usr/bin/python3 "${CMAKE_CURRENT_LIST_DIR}/test_graph.py" "${PROJECT_SOURCE_DIR}"
                 "${PROJECT_BINARY_DIR}/test-scratch/dem-tools-graph")
set_tests_properties(dem_tools_graph_extraction PROPERTIES LABELS "dem-tools;route")
