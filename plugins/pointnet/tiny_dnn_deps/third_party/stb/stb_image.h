#pragma once
// c3po's stand-in for stb_image (not a copy of it): Debian's tiny-dnn headers
// include "third_party/stb/..." for image file I/O, which the package does not
// ship. c3po never reads or writes images through tiny-dnn; these inline
// functions only let the headers compile and fail cleanly if ever called.
typedef unsigned char stbi_uc;
inline stbi_uc* stbi_load(const char*, int*, int*, int*, int) { return nullptr; }
inline const char* stbi_failure_reason() { return "image I/O is disabled in c3po's tiny-dnn build"; }
inline void stbi_image_free(void*) {}
