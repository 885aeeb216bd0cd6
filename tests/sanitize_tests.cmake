# ctest include file of an SF_SANITIZE build (tests/CMakeLists.txt): per-test sanitizer settings,
# applied after the GoogleTest discovery has defined the tests.
#
# LeakSanitizer records allocation stacks with the fast (frame pointer) unwinder, which stops at
# the first frame of a library built without frame pointers (libstdc++, OpenImageIO). A leak
# inside such a library then cannot be matched by a suppression naming it, so the tests that
# meet one unwind slowly (about 4x slower, hence not for every test).
#   ImageIoTest.TruncatedFilesAreReported: OpenImageIO's PNG reader leaks on a truncated file
#   (scripts/sanitize/lsan.supp).
set_tests_properties(ImageIoTest.TruncatedFilesAreReported PROPERTIES
  ENVIRONMENT_MODIFICATION "ASAN_OPTIONS=string_append::fast_unwind_on_malloc=0")
