// Casts the double given on the command line to int and prints it. With a value int cannot hold
// (nan, 1e10) the cast is undefined behaviour: the sanitized build must stop here with a
// float-cast-overflow report instead of printing a made-up int (GCC's `undefined` alone does not
// check float to int conversions). The value comes from argv so the compiler cannot fold the cast.
#include <cstdio>
#include <cstdlib>

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: float_cast_overflow VALUE\n");
    return 2;
  }
  const double value = std::strtod(argv[1], nullptr);
  const int cast = static_cast<int>(value);
  std::printf("cast %s to %d\n", argv[1], cast);
  return 0;
}
