# The MCAP writer, the Foxglove channel catalogue and the bridge's client protocol (tools/foxglove, tools/bridge).
caracara_unit_test(test_foxglove SOURCES unit/test_mcap_writer.cpp LIBS caracara_foxglove caracara_bridge_protocol)
