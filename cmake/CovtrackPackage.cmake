# covtrackd as a service (unit + default config, installed with the programs) and the
# Debian packages `cpack -G DEB` builds from the install components (docs/sdk.md):
#   covtrack      runtime + python: covtrackd, covtrack, covtrack-vision, the Python module,
#                 the lcm-spy jar, /etc/covtrack/covtrackd.toml (a conffile), covtrackd.service
#   covtrack-dev  dev: headers, static libraries, the CMake package, covtrack.pc
include(GNUInstallDirs)

install(CODE "
  set(COVTRACK_SERVICE_TEMPLATE \"${PROJECT_SOURCE_DIR}/packaging/covtrackd.service.in\")
  set(COVTRACK_DEFAULT_CONFIG \"${PROJECT_SOURCE_DIR}/config/sim.toml\")
  set(COVTRACK_BINDIR \"${CMAKE_INSTALL_BINDIR}\")
  set(COVTRACK_STAGING_DIR \"${PROJECT_BINARY_DIR}/packaging\")" COMPONENT runtime)
install(SCRIPT packaging/install_service.cmake COMPONENT runtime)

set(CPACK_PACKAGE_NAME covtrack)
set(CPACK_PACKAGE_VENDOR "covtrack")
set(CPACK_PACKAGE_CONTACT "covtrack maintainers <covtrack@localhost>")
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY "Tracker daemon publishing poses with 6x6 covariances over LCM")
set(CPACK_PACKAGE_VERSION ${PROJECT_VERSION})
set(CPACK_PACKAGE_DIRECTORY ${PROJECT_BINARY_DIR}/packages)
set(CPACK_GENERATOR DEB)
# Install with DESTDIR and the real prefix (CPACK_INSTALL_PREFIX, whatever the build's
# CMAKE_INSTALL_PREFIX), so that packaging/install_service.cmake sees /usr and puts the
# config in /etc.
set(CPACK_SET_DESTDIR ON)
set(CPACK_INSTALL_PREFIX /usr)
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
# Programs without their debug information (-g): some 100 MB each with it. Static
# libraries keep their symbols (CMake never strips them).
set(CPACK_STRIP_FILES ON)

set(CPACK_COMPONENTS_ALL runtime python dev)
set(CPACK_COMPONENT_RUNTIME_GROUP covtrack)
set(CPACK_COMPONENT_PYTHON_GROUP covtrack)
set(CPACK_COMPONENT_DEV_GROUP dev)
set(CPACK_DEB_COMPONENT_INSTALL ON)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_SECTION science)
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)  # dpkg-shlibdeps (dpkg-dev) lists the shared libraries

set(CPACK_DEBIAN_COVTRACK_PACKAGE_NAME covtrack)
set(CPACK_DEBIAN_COVTRACK_DESCRIPTION "covtrackd (tracker daemon), the covtrack command and the Python module
 covtrackd publishes every tracked pose with an honest 6x6 covariance over LCM; covtrack
 shows, records and replays the streams and computes screen-space error regions.")
# The Python module is built for one python3 version; shlibdeps cannot see that.
string(REGEX MATCH "python([0-9]+)\\.([0-9]+)" py "${COVTRACK_PYTHON_INSTALL_DIR}")
if(py)
  math(EXPR py_next "${CMAKE_MATCH_2} + 1")
  set(CPACK_DEBIAN_COVTRACK_PACKAGE_DEPENDS
      "python3 (>= ${CMAKE_MATCH_1}.${CMAKE_MATCH_2}), python3 (<< ${CMAKE_MATCH_1}.${py_next}), python3-numpy")
endif()
set(CPACK_DEBIAN_COVTRACK_PACKAGE_CONTROL_EXTRA
    ${PROJECT_SOURCE_DIR}/packaging/conffiles ${PROJECT_SOURCE_DIR}/packaging/postinst
    ${PROJECT_SOURCE_DIR}/packaging/prerm ${PROJECT_SOURCE_DIR}/packaging/postrm)
set(CPACK_DEBIAN_PACKAGE_CONTROL_STRICT_PERMISSION ON)

set(CPACK_DEBIAN_DEV_PACKAGE_NAME covtrack-dev)
set(CPACK_DEBIAN_DEV_DESCRIPTION "covtrack SDK: headers, libraries, CMake package and pkg-config file
 Client library (subscriber, transform graph, screen error regions), protocol and LCM log
 libraries; find_package(covtrack) or pkg-config covtrack.")
set(CPACK_DEBIAN_DEV_PACKAGE_DEPENDS
    "liblcm-dev, libsodium-dev, libeigen3-dev, libfmt-dev, libqhull-dev, libopencv-core-dev, libyaml-cpp-dev, libtinyxml2-dev")
include(CPack)
