#pragma once
// See stb_image.h: stand-in declarations for tiny-dnn's headers only.
inline int stbi_write_png(const char*, int, int, int, const void*, int) { return 0; }
inline int stbi_write_bmp(const char*, int, int, int, const void*) { return 0; }
