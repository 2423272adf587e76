# SPDX-License-Identifier: Apache-2.0
# Project-wide compile settings: warnings, sanitizers, fuzzing.

if(CMAKE_C_COMPILER_ID MATCHES "GNU|Clang")
  set(POSE_WARNING_FLAGS -Wall -Wextra -Wshadow -Wstrict-prototypes -Wmissing-prototypes
                         -Wno-unused-parameter)
  if(POSE_WERROR)
    list(APPEND POSE_WARNING_FLAGS -Werror)
  endif()
endif()

# pose_target_warnings(<target>): the project's warning set on one of its own targets
# (C sources only; C++ shims get -Wall -Wextra).
function(pose_target_warnings target)
  target_compile_options(${target} PRIVATE
    $<$<COMPILE_LANGUAGE:C>:${POSE_WARNING_FLAGS}>
    $<$<COMPILE_LANGUAGE:CXX>:-Wall -Wextra $<$<BOOL:${POSE_WERROR}>:-Werror>>)
endfunction()

if(POSE_SANITIZE AND POSE_TSAN)
  message(FATAL_ERROR "POSE_SANITIZE and POSE_TSAN cannot be combined")
endif()
# Undefined behaviour aborts (-fno-sanitize-recover=all) in every sanitized
# build: in recover mode UBSan only logs, so ctest passes and libFuzzer never
# saves the input as a crash.
if(POSE_SANITIZE)
  add_compile_options(-fsanitize=address,undefined -fno-sanitize-recover=all -fno-omit-frame-pointer)
  add_link_options(-fsanitize=address,undefined -fno-sanitize-recover=all)
endif()
if(POSE_TSAN)
  add_compile_options(-fsanitize=thread -fno-omit-frame-pointer)
  add_link_options(-fsanitize=thread)
endif()
if(POSE_FUZZ)
  if(NOT CMAKE_C_COMPILER_ID MATCHES "Clang")
    message(FATAL_ERROR "POSE_FUZZ needs clang (CC=clang)")
  endif()
  # Instrument everything for coverage; the fuzzer main is linked only into fuzz targets.
  add_compile_options(-fsanitize=fuzzer-no-link,address,undefined -fno-sanitize-recover=all)
  add_link_options(-fsanitize=address,undefined -fno-sanitize-recover=all)
endif()

find_package(Threads REQUIRED)

# The platform files: <name>_posix.c or <name>_win32.c (runtime/rt_thread_*,
# sdk/src/platform_map_*); a source folder's glob drops both and adds the one
# pose_platform_sources names. Windows builds use Win32 threads, never winpthreads.
if(WIN32)
  set(POSE_PLATFORM win32)
  # mingw-w64's C99 printf family (%zu, %lld), not msvcrt's. To mingw's gcc
  # format(printf) still names msvcrt's, so it would reject %zu: format
  # strings are checked by the Linux builds.
  add_compile_definitions(__USE_MINGW_ANSI_STDIO=1)
  list(APPEND POSE_WARNING_FLAGS -Wno-format)
  set(POSE_THREAD_LIBS "")
else()
  set(POSE_PLATFORM posix)
  set(POSE_THREAD_LIBS Threads::Threads)
endif()
# pose_platform_sources(<list var> <dir> <name>...): filter <list var> to this platform.
function(pose_platform_sources var dir)
  set(sources ${${var}})
  list(FILTER sources EXCLUDE REGEX "_(posix|win32)\\.c$")
  foreach(name IN LISTS ARGN)
    list(APPEND sources "${dir}/${name}_${POSE_PLATFORM}.c")
  endforeach()
  set(${var} ${sources} PARENT_SCOPE)
endfunction()
