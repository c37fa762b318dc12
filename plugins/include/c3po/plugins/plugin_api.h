/* c3po detector plugin C entry point (stable ABI, plain C).
 *
 * A shared library becomes a c3po detector by exporting
 *
 *   const struct c3po_detector_plugin* c3po_detector_plugin_v1(void);
 *
 * returning a pointer to a static table. c3po calls `create` once per object
 * with the object's keypoints in the model frame (3*N doubles, point-major
 * x0 y0 z0 x1 ...), the object diameter and, if --model was given, the model
 * file path (else NULL). `detect` receives a cloud of n points (3*n doubles,
 * point-major) and writes N keypoints (3*N doubles) in the cloud's frame; it
 * returns 0 on success, non-zero on failure (then `last_error` may explain).
 * `detect` must be callable from several threads at once on one instance.
 *
 * Load with: c3po certify OBJ --plugin ./libmydet.so --detector NAME ...
 */
#ifndef C3PO_PLUGIN_API_H
#define C3PO_PLUGIN_API_H

#ifdef __cplusplus
extern "C" {
#endif

#define C3PO_PLUGIN_ABI_VERSION 1

struct c3po_detector_plugin {
  int abi_version;                 /* C3PO_PLUGIN_ABI_VERSION */
  const char* name;                /* registry name, e.g. "mydet" */
  const char* description;
  void* (*create)(const double* model_keypoints, int num_keypoints, double diameter,
                  const char* model_path);
  void (*destroy)(void* instance);
  int (*detect)(void* instance, const double* cloud, int num_points, double* keypoints_out);
  const char* (*last_error)(void* instance); /* may be NULL */
};

typedef const struct c3po_detector_plugin* (*c3po_detector_plugin_entry)(void);

#ifdef __cplusplus
}
#endif

#endif /* C3PO_PLUGIN_API_H */
