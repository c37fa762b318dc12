#pragma once
// See stb_image.h: stand-in declarations for tiny-dnn's headers only.
inline int stbir_resize_uint8(const unsigned char*, int, int, int, unsigned char*, int, int, int, int) { return 0; }
inline int stbir_resize_float(const float*, int, int, int, float*, int, int, int, int) { return 0; }
