// A shared library that registers no plugin (e.g. the wrong target was built): loading it as a plugin library is
// an error.

extern "C" int redres_test_plugin_empty_marker() { return 42; }
