# SPDX-License-Identifier: Apache-2.0
# Install rules: headers, libraries, find_package(pose) config and pose.pc.
include(CMakePackageConfigHelpers)

# What the package config and pose_bridge.pc say about the bridge.
if(TARGET pose_bridge)
  set(POSE_CONFIG_BRIDGE TRUE)
else()
  set(POSE_CONFIG_BRIDGE FALSE)
endif()
if(POSE_BRIDGE_HAVE_HIDAPI)
  set(POSE_CONFIG_HIDAPI TRUE)
  string(APPEND POSE_BRIDGE_PC_LIBS_PRIVATE " -lhidapi-hidraw")
else()
  set(POSE_CONFIG_HIDAPI FALSE)
endif()
if(POSE_BRIDGE_HAVE_LIBUSB)
  set(POSE_CONFIG_LIBUSB TRUE)
  string(APPEND POSE_BRIDGE_PC_LIBS_PRIVATE " -lusb-1.0")
  if(CMAKE_DL_LIBS) # usb_hid.c loads hidapi's libusb backend with dlmopen
    string(APPEND POSE_BRIDGE_PC_LIBS_PRIVATE " -l${CMAKE_DL_LIBS}")
  endif()
else()
  set(POSE_CONFIG_LIBUSB FALSE)
endif()

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
if(POSE_CONFIG_BRIDGE)
  configure_file("${PROJECT_SOURCE_DIR}/cmake/pose_bridge.pc.in" "${PROJECT_BINARY_DIR}/pose_bridge.pc" @ONLY)
  install(FILES "${PROJECT_BINARY_DIR}/pose_bridge.pc" DESTINATION "${CMAKE_INSTALL_LIBDIR}/pkgconfig")
endif()
install(FILES "${PROJECT_SOURCE_DIR}/LICENSE" DESTINATION "${CMAKE_INSTALL_DATADIR}/doc/pose" OPTIONAL)

# pose_install_ready: every target `cmake --install` copies, and nothing else
# (not the tests), so a build of just the tools and libraries can be installed:
# scripts/demo.sh builds this. tests/examples/install_ready.sh checks that the
# list covers every file the install rules take from the build tree.
add_custom_target(pose_install_ready)
foreach(tgt IN ITEMS pose pose_static pose_synth pose_bridge pose_bridge_static
                     pose-synth pose-bake pose-bridge pose-render pose-view pose-export
                     pose-volume)
  if(TARGET ${tgt})
    add_dependencies(pose_install_ready ${tgt})
  endif()
endforeach()
