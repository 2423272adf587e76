# SPDX-License-Identifier: Apache-2.0
# USB backend (bridge/src/usb) link dependencies, included by bridge/CMakeLists.txt
# after the bridge targets exist. libusb 1.0 (LGPL-2.1, linked dynamically) is
# optional: without it usbmon captures, the frame decoder and the simulated
# devices still build; live vendor-class devices report POSE_ERR_UNSUPPORTED.
pkg_check_modules(LIBUSB IMPORTED_TARGET libusb-1.0)
if(LIBUSB_FOUND)
  # dl: hidapi's libusb backend is loaded at run time (usb_hid.c), beside the hidraw one the HID family links.
  pose_bridge_link(PkgConfig::LIBUSB ${CMAKE_DL_LIBS})
  pose_bridge_define(POSE_BRIDGE_HAVE_LIBUSB=1)
  set(POSE_BRIDGE_HAVE_LIBUSB ON PARENT_SCOPE)
else()
  message(STATUS "pose-bridge: libusb-1.0 not found; live vendor-class USB devices disabled (usbmon captures still replay)")
endif()

# Generator of the reference USB goniometer captures in data/usb/ (reproducible).
add_executable(pose-usb-gonio-gen "${CMAKE_CURRENT_SOURCE_DIR}/devices/usb_gonio_gen.c")
target_link_libraries(pose-usb-gonio-gen PRIVATE pose_bridge_internal)
target_compile_definitions(pose-usb-gonio-gen PRIVATE _POSIX_C_SOURCE=200809L)
pose_target_warnings(pose-usb-gonio-gen)
install(FILES "${CMAKE_CURRENT_SOURCE_DIR}/devices/70-pose-usb-gonio.rules"
              "${CMAKE_CURRENT_SOURCE_DIR}/devices/USB_GONIOMETER.md"
        DESTINATION "${CMAKE_INSTALL_DATADIR}/pose/devices")
