# Reliability (issue 9): the test-only recorder that the SIGKILL test starts and kills.
# Included by tests/CMakeLists.txt after test_reliability is defined.
add_executable(reliability_record_child "${CMAKE_CURRENT_LIST_DIR}/record_child.cpp")
target_link_libraries(reliability_record_child PRIVATE pdnav::io)
if(TARGET test_reliability)
  add_dependencies(test_reliability reliability_record_child)
  target_compile_definitions(test_reliability PRIVATE
    PDNAV_RECORD_CHILD="$<TARGET_FILE:reliability_record_child>")
  target_include_directories(test_reliability PRIVATE "${CMAKE_CURRENT_LIST_DIR}")
endif()
