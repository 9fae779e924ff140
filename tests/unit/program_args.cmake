# The programs' command line (drivers/sdbus/program_args): option forms, values, the bus options.
caracara_unit_test(test_program_args SOURCES unit/test_program_args.cpp LIBS caracara_sdbus)
