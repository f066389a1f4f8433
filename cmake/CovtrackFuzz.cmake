# -DCOVTRACK_FUZZ=ON: every library and the fuzz harnesses of tests/fuzz are built with
# libFuzzer's coverage, AddressSanitizer and UndefinedBehaviorSanitizer (clang only).
# tests/fuzz/run_fuzzers.sh configures such a tree of its own and runs the harnesses.
if(NOT CMAKE_CXX_COMPILER_ID STREQUAL "Clang")
  message(FATAL_ERROR "COVTRACK_FUZZ needs clang (libFuzzer): -DCMAKE_CXX_COMPILER=clang++-16 "
                      "-DCMAKE_C_COMPILER=clang-16 (Debian: clang-16, libclang-rt-16-dev)")
endif()
# Any sanitizer report ends the run, so that libFuzzer keeps the input that caused it.
add_compile_options(-fsanitize=fuzzer-no-link,address,undefined -fno-sanitize-recover=all
                    -fno-omit-frame-pointer)
add_link_options(-fsanitize=address,undefined)

# libstdc++ 12 offers <expected> only when __cpp_concepts says C++20's concepts in full
# (202002L); clang 16 implements what <expected> needs (conditionally trivial special
# members) but still reports 201907L. Without <expected> no covtrack header compiles.
include(CheckCXXSourceCompiles)
set(CMAKE_REQUIRED_FLAGS -std=c++2b)
check_cxx_source_compiles("#include <expected>\nint main() { std::expected<int, int> e = 1; return *e - 1; }"
                          COVTRACK_HAVE_EXPECTED)
if(NOT COVTRACK_HAVE_EXPECTED)
  set(CMAKE_REQUIRED_FLAGS "-std=c++2b -U__cpp_concepts -D__cpp_concepts=202002L")
  check_cxx_source_compiles("#include <expected>\nint main() { std::expected<int, int> e = 1; return *e - 1; }"
                            COVTRACK_HAVE_EXPECTED_WITH_CONCEPTS)
  if(NOT COVTRACK_HAVE_EXPECTED_WITH_CONCEPTS)
    message(FATAL_ERROR "this clang cannot compile libstdc++'s <expected>: use clang 16 or newer")
  endif()
  add_compile_options($<$<COMPILE_LANGUAGE:CXX>:-U__cpp_concepts> $<$<COMPILE_LANGUAGE:CXX>:-D__cpp_concepts=202002L>)
endif()
unset(CMAKE_REQUIRED_FLAGS)
