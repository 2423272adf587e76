# SPDX-License-Identifier: Apache-2.0
# Install rules: headers, libraries, find_package(pose) config and pose.pc.
include(CMakePackageConfigHelpers)

install(DIRECTORY "${PROJECT_SOURCE_DIR}/sdk/include/pose"
        DESTINATION "${CMAKE_INSTALL_INCLUDEDIR}")
install(EXPORT poseTargets NAMESPACE pose::
        DESTINATION "${CMAKE_INSTALL_LIBDIR}/cmake/pose")
configure_package_config_file("${PROJECT_SOURCE_DIR}/cmake/poseConfig.cmake.in"
  "${PROJECT_BINARY_DIR}/poseConfig.cmake"
  INSTALL_DESTINATION "${CMAKE_INSTALL_LIBDIR}/cmake/pose")
write_basic_package_version_file("${PROJECT_BINARY_DIR}/poseConfigVersion.cmake"
  COMPATIBILITY SameMajorVersion)
install(FILES "${PROJECT_BINARY_DIR}/poseConfig.cmake" "${PROJECT_BINARY_DIR}/poseConfigVersion.cmake"
        DESTINATION "${CMAKE_INSTALL_LIBDIR}/cmake/pose")

# pose.pc finds its prefix relative to itself, so `cmake --install --prefix X` works.
file(RELATIVE_PATH POSE_PC_UP "${CMAKE_INSTALL_FULL_LIBDIR}/pkgconfig" "${CMAKE_INSTALL_PREFIX}")
configure_file("${PROJECT_SOURCE_DIR}/cmake/pose.pc.in" "${PROJECT_BINARY_DIR}/pose.pc" @ONLY)
install(FILES "${PROJECT_BINARY_DIR}/pose.pc" DESTINATION "${CMAKE_INSTALL_LIBDIR}/pkgconfig")
install(FILES "${PROJECT_SOURCE_DIR}/LICENSE" DESTINATION "${CMAKE_INSTALL_DATADIR}/doc/pose" OPTIONAL)
