# The MCAP writer, the Foxglove channel catalogue, the bridge's client protocol, send queue, client slots, static files and Origin check, and caracaractl bridge's key (tools/foxglove, tools/bridge, tools/caracaractl).
caracara_unit_test(test_foxglove SOURCES unit/test_mcap_writer.cpp unit/test_send_queue.cpp unit/test_client_slots.cpp
                   unit/test_static_files.cpp unit/test_origin_check.cpp
                   unit/test_forward_key.cpp
                   LIBS caracara_foxglove caracara_bridge_protocol caracara_bridge_files caracara_ctl_forward_key)
