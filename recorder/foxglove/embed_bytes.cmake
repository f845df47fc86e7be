# Writes OUT, a C++ file defining NAME (a byte array) and NAME_size with the
# bytes of IN: a file compiled into the program rather than read at run time.
file(READ "${IN}" hex HEX)
string(LENGTH "${hex}" digits)
math(EXPR size "${digits} / 2")
string(REGEX REPLACE "([0-9a-f][0-9a-f])" "0x\\1," bytes "${hex}")
file(WRITE "${OUT}"
  "// Generated from ${IN} by embed_bytes.cmake.\n"
  "#include <cstddef>\n"
  "namespace wircam::recorder {\n"
  "extern const unsigned char ${NAME}[] = {${bytes}};\n"
  "extern const std::size_t ${NAME}_size = ${size};\n"
  "}  // namespace wircam::recorder\n")
