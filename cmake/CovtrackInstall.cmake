# The SDK that `cmake --install` puts under the prefix: the client, protocol and log
# libraries (static, position independent), their headers and the LCM message headers
# they include, a CMake package (find_package(covtrack): covtrack::client,
# covtrack::protocol, covtrack::log, covtrack::camera; covtrack::osg when built) and
# covtrack.pc. docs/sdk.md.
# Everything here is the "dev" component; the programs are "runtime", the Python module
# "python".
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

set(COVTRACK_CMAKE_DIR ${CMAKE_INSTALL_LIBDIR}/cmake/covtrack)
set_target_properties(covtrack_protocol PROPERTIES EXPORT_NAME protocol)
set_target_properties(covtrack_camera PROPERTIES EXPORT_NAME camera)
set_target_properties(covtrack_client PROPERTIES EXPORT_NAME client)
# The client's parts (client/CMakeLists.txt), which covtrack::client links.
foreach(part streams graph regions widgets)
  set_target_properties(covtrack_client_${part} PROPERTIES EXPORT_NAME client_${part})
endforeach()
set_target_properties(covtrack_lcmlog PROPERTIES EXPORT_NAME log)

install(TARGETS covtrack_protocol covtrack_camera covtrack_client_streams covtrack_client_graph covtrack_client_regions
                covtrack_client_widgets covtrack_client covtrack_lcmlog
        EXPORT covtrackTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR} COMPONENT dev
        INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(DIRECTORY protocol/include/ protocol/camera/include/ client/streams/include/ client/graph/include/
                  client/regions/include/ client/widgets/include/ client/ar_view/include/
                  tools/lcmlog/include/
        DESTINATION ${CMAKE_INSTALL_INCLUDEDIR} COMPONENT dev)
# lcm-gen's headers (covtrack/pose_cov_t.hpp, ...), which the public headers include.
install(DIRECTORY ${PROJECT_BINARY_DIR}/protocol/lcmgen/covtrack
        DESTINATION ${CMAKE_INSTALL_INCLUDEDIR} COMPONENT dev FILES_MATCHING PATTERN "*.hpp")
install(EXPORT covtrackTargets NAMESPACE covtrack:: DESTINATION ${COVTRACK_CMAKE_DIR} COMPONENT dev)

# The OpenSceneGraph adapter, when it was built: find_package(covtrack COMPONENTS osg)
# gives covtrack::osg (its own export set, so that the rest needs no OpenSceneGraph).
if(TARGET covtrack_osg)
  set_target_properties(covtrack_osg PROPERTIES EXPORT_NAME osg)
  install(TARGETS covtrack_osg EXPORT covtrackOsgTargets
          ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR} COMPONENT dev
          INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
  install(DIRECTORY client/osg/include/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR} COMPONENT dev)
  install(EXPORT covtrackOsgTargets NAMESPACE covtrack:: DESTINATION ${COVTRACK_CMAKE_DIR} COMPONENT dev)
endif()

configure_package_config_file(cmake/covtrackConfig.cmake.in ${PROJECT_BINARY_DIR}/covtrackConfig.cmake
                              INSTALL_DESTINATION ${COVTRACK_CMAKE_DIR})
# 0.x: a minor release may change the API.
write_basic_package_version_file(${PROJECT_BINARY_DIR}/covtrackConfigVersion.cmake
                                 COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/covtrackConfig.cmake ${PROJECT_BINARY_DIR}/covtrackConfigVersion.cmake
        DESTINATION ${COVTRACK_CMAKE_DIR} COMPONENT dev)

# pkg-config: the prefix is found from the .pc file's own place, so that the file is
# right wherever the tree is installed (`cmake --install --prefix`, a Debian package).
set(pc_dir ${CMAKE_INSTALL_LIBDIR}/pkgconfig)
file(RELATIVE_PATH COVTRACK_PC_TO_PREFIX /prefix/${pc_dir} /prefix)
string(REGEX REPLACE "/$" "" COVTRACK_PC_TO_PREFIX "${COVTRACK_PC_TO_PREFIX}")
configure_file(cmake/covtrack.pc.in ${PROJECT_BINARY_DIR}/covtrack.pc @ONLY)
install(FILES ${PROJECT_BINARY_DIR}/covtrack.pc DESTINATION ${pc_dir} COMPONENT dev)
