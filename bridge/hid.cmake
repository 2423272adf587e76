# SPDX-License-Identifier: Apache-2.0
# HID backend link dependencies (included by bridge/CMakeLists.txt after the
# bridge targets exist). hidapi's hidraw backend (BSD/GPL/original
# hidapi licence, used under its permissive terms) is optional: without it the
# recordings, the decoder and the simulated devices still build; live devices
# report POSE_ERR_UNSUPPORTED.
pkg_check_modules(HIDAPI IMPORTED_TARGET hidapi-hidraw)
if(HIDAPI_FOUND)
  pose_bridge_link(PkgConfig::HIDAPI)
  pose_bridge_define(POSE_BRIDGE_HAVE_HIDAPI=1)
  set(POSE_BRIDGE_HAVE_HIDAPI ON PARENT_SCOPE)
else()
  message(STATUS "pose-bridge: hidapi-hidraw not found; live HID devices disabled (recordings still work)")
endif()


# Generator of the reference mannequin recordings in data/hid/ (reproducible).
add_executable(pose-hid-mannequin-gen "${CMAKE_CURRENT_SOURCE_DIR}/devices/mannequin_gen.c")
target_link_libraries(pose-hid-mannequin-gen PRIVATE pose_bridge_internal)
target_compile_definitions(pose-hid-mannequin-gen PRIVATE _POSIX_C_SOURCE=200809L)
pose_target_warnings(pose-hid-mannequin-gen)

# Hardware builders' material: the udev rule for non-root access and its README
# (copy the rule to /etc/udev/rules.d, see the README).
install(FILES "${CMAKE_CURRENT_SOURCE_DIR}/devices/70-pose-mannequin.rules"
              "${CMAKE_CURRENT_SOURCE_DIR}/devices/README.md"
        DESTINATION "${CMAKE_INSTALL_DATADIR}/pose/devices")
