# pdr: the `pdnav steps` command on real data (Oxford bar) and on a session log.
set(_pdr_oxford "${PDNAV_SHARED_DATA_DIR}/steps-oxford")
add_test(NAME pdr_cli_steps_oxford_table
         COMMAND pdnav steps --format oxford --table --check-mean 3 --check-worst 8
                 "${_pdr_oxford}/user1_armband_1506423438471.csv"
                 "${_pdr_oxford}/user1_backpocket_1506422470497.csv"
                 "${_pdr_oxford}/user1_bag_1506423095164.csv"
                 "${_pdr_oxford}/user1_frontpocket_1506422223341.csv"
                 "${_pdr_oxford}/user1_hand_1506421989895.csv"
                 "${_pdr_oxford}/user1_neckpouch_1506422851785.csv")
set_tests_properties(pdr_cli_steps_oxford_table PROPERTIES LABELS "pdr;cli"
                     PASS_REGULAR_EXPRESSION "mean \\|error\\| [0-9.]+ %.*steps: [0-9]+")

# The log fixture is written by the gtest PdrLogReplay.WriteCliFixture.
add_test(NAME pdr_cli_log_fixture COMMAND test_pdr --gtest_filter=PdrLogReplay.WriteCliFixture)
set_tests_properties(pdr_cli_log_fixture PROPERTIES LABELS "pdr" FIXTURES_SETUP pdr_cli_log)
add_test(NAME pdr_cli_steps_log
         COMMAND pdnav steps "${PROJECT_BINARY_DIR}/test-scratch/pdr-cli/walk.txt")
set_tests_properties(pdr_cli_steps_log PROPERTIES LABELS "pdr;cli" FIXTURES_REQUIRED pdr_cli_log
                     PASS_REGULAR_EXPRESSION "turn at [0-9.]+ s .*, (8[0-9]|9[0-9]|100) deg, left.*steps: (4[89]|5[0-9]|6[0-2])\n")
