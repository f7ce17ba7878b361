# Bounds the lengths that lcm-gen's C++ decoders (lcm 1.3.1) trust before they allocate: run on every
# generated header right after lcm-gen (`cmake -DGEN_DIR=<dir> -P harden_decoders.cmake`).
#
# Found by fuzzing (tests/fuzz, tools/fuzz): a corrupt message made a decoder
#   - resize an array to its count before checking that the bytes are there (num_points = 2^31 - 1
#     allocates 8 GB, a struct array far more; a negative count threw std::length_error), and
#   - take a string length of 0 or below (len - 1 overflows at INT32_MIN; a negative length threw).
# Every array element takes at least one byte and every LCM string at least its terminating NUL, so a
# count above the bytes left, or a string length below 1, is a corrupt message: decode() returns -1 as
# it does for any other corrupt message. Valid messages decode exactly as before.
if(NOT GEN_DIR)
  message(FATAL_ERROR "harden_decoders: pass -DGEN_DIR=<folder of the generated headers>")
endif()

file(GLOB headers "${GEN_DIR}/fusecal/*.hpp")
if(NOT headers)
  message(FATAL_ERROR "harden_decoders: no generated headers in ${GEN_DIR}/fusecal")
endif()
foreach(header IN LISTS headers)
  file(READ "${header}" code)
  # if(__name_len__ > maxlen - pos) return -1;   (and __elem_len in string arrays)
  string(REGEX REPLACE "if\\((__[A-Za-z0-9_]+) > maxlen - pos\\) return -1;"
         "if(\\1 < 1 || \\1 > maxlen - pos) return -1;" code "${code}")
  # this->x.resize(this->num_points);   (not the fixed inner size of a 2-D array: resize(16))
  string(REGEX REPLACE "\n( *)this->([A-Za-z0-9_]+)\\.resize\\(this->([A-Za-z0-9_]+)\\);"
         "\n\\1if(this->\\3 < 0 || this->\\3 > maxlen - pos) return -1;\n\\1this->\\2.resize(this->\\3);"
         code "${code}")
  # A later lcm-gen that writes these lines differently must not slip through unchecked.
  if(code MATCHES "if\\(__[A-Za-z0-9_]+ > maxlen - pos\\)")
    message(FATAL_ERROR "harden_decoders: ${header}: a string length is still unchecked")
  endif()
  string(REPLACE ";" "#" flat "${code}")  # semicolons would split the lists of matches
  string(REGEX MATCHALL "resize\\(this->[A-Za-z0-9_]+\\)#" resizes "${flat}")
  string(REGEX MATCHALL "> maxlen - pos\\) return -1#\n *this->[A-Za-z0-9_]+\\.resize\\(this->" guarded "${flat}")
  list(LENGTH resizes resize_count)
  list(LENGTH guarded guarded_count)
  if(NOT resize_count EQUAL guarded_count)
    message(FATAL_ERROR "harden_decoders: ${header}: ${resize_count} array resizes, ${guarded_count} checked")
  endif()
  file(WRITE "${header}" "${code}")
endforeach()
