#!/bin/sh
# Doxygen INPUT_FILTER for include/fins: the headers document their contracts in plain
# // comments (house style); this makes them doc comments (/// before a declaration,
# ///< after a member) and hides the std::is_error_code_enum specialisations, which
# Doxygen 1.9 cannot place in a scope. Line numbers are kept.
exec sed -e '/^template <>$/{N;/is_error_code_enum/s/.*/\n/;}' \
  -e 's%^\([[:space:]]*\)//\( \|$\)%\1///\2%' \
  -e 's|\([;,]\)\([[:space:]]*\)// |\1\2///< |' "$1"
