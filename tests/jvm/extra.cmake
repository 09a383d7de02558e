# JVM tests of the Kotlin API and the app (tests/jvm/src), and the debug APK check.
# Both run Maven through tools/ scripts; versions come from gradle/libs.versions.toml.
# Label `jvm`: tools/android-host/run (compile all app sources, JUnit bridge tests with the
# host-built libpdnav_jni.so, Robolectric). Label `apk`: tools/apk (assemble + verify).
if(NOT PDNAV_BUILD_JVM_TESTS)
  return()
endif()

if(NOT TARGET pdnav_jni)
  # Without JDK headers the bridge is not built; say so as a failing test, not a silent skip.
  add_test(NAME jvm_bridge_missing
           COMMAND ${CMAKE_COMMAND} -E echo "pdnav_jni not built: no JDK found (tools/setup installs default-jdk-headless)")
  set_tests_properties(jvm_bridge_missing PROPERTIES LABELS "jvm" WILL_FAIL TRUE)
  return()
endif()

find_program(PDNAV_MVN mvn)
find_program(PDNAV_AAPT2 aapt2)
if(NOT PDNAV_MVN OR NOT PDNAV_AAPT2)
  message(WARNING "pdnav: mvn or aapt2 missing (tools/setup installs them); JVM tests will fail")
endif()

set(_pdnav_android_out "${PROJECT_BINARY_DIR}/android-host")
add_test(NAME jvm_app_and_bridge
         COMMAND "${PROJECT_SOURCE_DIR}/tools/android-host/run"
                 --out "${_pdnav_android_out}"
                 --jni-lib "$<TARGET_FILE:pdnav_jni>"
                 --cli "$<TARGET_FILE:pdnav>"
                 --shared-data "${PDNAV_SHARED_DATA_DIR}")
# RESOURCE_LOCK: the two Maven runs share ~/.m2 and would fight for the 2 cores.
set_tests_properties(jvm_app_and_bridge PROPERTIES LABELS "jvm" TIMEOUT 900 RESOURCE_LOCK pdnav_maven)

add_test(NAME apk_debug_assemble_verify
         COMMAND "${PROJECT_SOURCE_DIR}/tools/apk" --out "${PROJECT_BINARY_DIR}/apk"
                 --host-out "${_pdnav_android_out}")
set_tests_properties(apk_debug_assemble_verify PROPERTIES LABELS "apk" TIMEOUT 900 RESOURCE_LOCK pdnav_maven)

# ---- issue 21: pictures of every screen (begin) ----
# ScreensRoboTest (run inside jvm_app_and_bridge, Robolectric native graphics) writes one PNG
# per screen to ${_pdnav_android_out}/screens; this lists them and fails when one is missing.
set_tests_properties(jvm_app_and_bridge PROPERTIES FIXTURES_SETUP pdnav_screens)
add_test(NAME jvm_screen_pictures
         COMMAND /usr/bin/python3 "${CMAKE_CURRENT_LIST_DIR}/check_screens.py" "${_pdnav_android_out}/screens"
                 main-map permission-explanation sessions settings satellites
                 main-walker main-details regions goto goto-uncertain places out-of-region)
set_tests_properties(jvm_screen_pictures PROPERTIES LABELS "jvm" FIXTURES_REQUIRED pdnav_screens)
# ---- issue 21 (end) ----
