// Which sanitizer instruments this test program, for GCC and Clang alike.
// GCC defines __SANITIZE_ADDRESS__ / __SANITIZE_THREAD__; Clang 14 (the
// sanitizer pass of scripts/test.sh) answers through __has_feature instead.
//   SWEETSPOT_UNDER_ASAN  1 under AddressSanitizer, else 0
//   SWEETSPOT_UNDER_TSAN  1 under ThreadSanitizer, else 0
#pragma once

#if defined(__SANITIZE_ADDRESS__)
#define SWEETSPOT_UNDER_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define SWEETSPOT_UNDER_ASAN 1
#endif
#endif
#ifndef SWEETSPOT_UNDER_ASAN
#define SWEETSPOT_UNDER_ASAN 0
#endif

#if defined(__SANITIZE_THREAD__)
#define SWEETSPOT_UNDER_TSAN 1
#elif defined(__has_feature)
#if __has_feature(thread_sanitizer)
#define SWEETSPOT_UNDER_TSAN 1
#endif
#endif
#ifndef SWEETSPOT_UNDER_TSAN
#define SWEETSPOT_UNDER_TSAN 0
#endif
