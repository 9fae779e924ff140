# The one version (tests/release/check_version.py): project(VERSION) is what the three programs'
# --version, the manual pages, debian/changelog, CHANGELOG.md and README.md say.
add_test(NAME version
         COMMAND /usr/bin/python3 ${CMAKE_CURRENT_LIST_DIR}/check_version.py
                 ${PROJECT_VERSION} ${CMAKE_SOURCE_DIR} ${CMAKE_BINARY_DIR})
set_tests_properties(version PROPERTIES LABELS release ENVIRONMENT "${CARACARA_TEST_ENV}")
