/* SPDX-License-Identifier: Apache-2.0 */
#ifndef POSE_EXPORT_H
#define POSE_EXPORT_H

/* Symbols not marked POSE_API are hidden: the library is built with
 * -fvisibility=hidden and only the public API is exported. */
#if defined(_WIN32) && !defined(POSE_STATIC)
#  if defined(POSE_BUILDING)
#    define POSE_API __declspec(dllexport)
#  else
#    define POSE_API __declspec(dllimport)
#  endif
#elif defined(__GNUC__) || defined(__clang__)
#  define POSE_API __attribute__((visibility("default")))
#else
#  define POSE_API
#endif

#endif /* POSE_EXPORT_H */
