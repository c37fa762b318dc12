// A shared library without the c3po entry point: the loader must reject it.
extern "C" int c3po_test_unrelated_function(int x) { return 2 * x + 1; }
