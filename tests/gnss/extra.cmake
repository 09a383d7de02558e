# Issue 7 bar through the CLI on the real Mountain View log (the GoogleTest
# SolverMountainView.* checks the same numbers through the library).
add_test(NAME gnss.cli_mountainview_bar
  COMMAND /usr/bin/python3 "${CMAKE_CURRENT_SOURCE_DIR}/gnss/check_cli_bar.py" "$<TARGET_FILE:pdnav>" "${PDNAV_SHARED_DATA_DIR}")
set_tests_properties(gnss.cli_mountainview_bar PROPERTIES LABELS "gnss;cli" TIMEOUT 300)

# Broadcast ephemeris vs precise SP3 orbits (the truth check of the multi-GNSS orbit code).
add_test(NAME gnss.cli_orbits_sp3_bar
  COMMAND /usr/bin/python3 "${CMAKE_CURRENT_SOURCE_DIR}/gnss/check_orbits_bar.py" "$<TARGET_FILE:pdnav>" "${PDNAV_SHARED_DATA_DIR}")
set_tests_properties(gnss.cli_orbits_sp3_bar PROPERTIES LABELS "gnss;cli" TIMEOUT 120)

# Issue 15: `pdnav rinex` output is read by RTKLIB (rnx2rtkp, Debian rtklib) and its single
# point solution agrees with pdnav's SPP on the same file.
add_test(NAME gnss.rtklib_reads_pdnav_rinex
  COMMAND /usr/bin/python3 "${CMAKE_CURRENT_SOURCE_DIR}/gnss/check_rtklib_rinex.py" "$<TARGET_FILE:pdnav>" "${PDNAV_SHARED_DATA_DIR}")
set_tests_properties(gnss.rtklib_reads_pdnav_rinex PROPERTIES LABELS "gnss;cli" TIMEOUT 300)

# Issue 15 part A: the kinematic KF on the GSDC drive, continuous and duty cycled (5 s, no ADR).
add_test(NAME gnss.cli_gsdc_kinematic_kf
  COMMAND /usr/bin/python3 "${CMAKE_CURRENT_SOURCE_DIR}/gnss/check_gsdc_kf.py" "$<TARGET_FILE:pdnav>" "${PDNAV_SHARED_DATA_DIR}")
set_tests_properties(gnss.cli_gsdc_kinematic_kf PROPERTIES LABELS "gnss;cli" TIMEOUT 120)

# Issue 15: the per-signal code noise defaults are reproduced by tools/gnss-noise-fit from the
# shared GSDC and Mountain View residuals at the truth (docs/gnss.md "Code noise model").
add_test(NAME gnss.noise_model_fit_reproduces_defaults
  COMMAND /usr/bin/python3 "${CMAKE_CURRENT_SOURCE_DIR}/gnss/check_noise_fit.py" "$<TARGET_FILE:pdnav>"
          "${PDNAV_SHARED_DATA_DIR}" "${CMAKE_CURRENT_SOURCE_DIR}/..")
set_tests_properties(gnss.noise_model_fit_reproduces_defaults PROPERTIES LABELS "gnss;cli" TIMEOUT 300)
