#!/usr/bin/env bash
# The function-length checker must flag an 81-line function, a long member
# function defined in a class, and a long namespace-scope initializer, and
# pass an 80-line one (braces in comments and strings do not count).
set -euo pipefail
checker="$1"; work="$2"
rm -rf "$work"; mkdir -p "$work/src"
body() { for i in $(seq "$1"); do echo "  x += $i;  // { not a brace"; done; }
{
  echo "namespace a {"
  echo "int ok() {"; echo "  int x = 0;"; body 76; echo "  return x;"; echo "}"          # 80 lines
  echo "int tooLong() {"; echo "  int x = 0;"; body 77; echo "  return x;"; echo "}"     # 81 lines
  echo "struct S {"; echo "  int member() {"; echo '    const char* s = "}}}";'; echo "    int x = 0;"; body 80; echo "    return x;"; echo "  }"; echo "};"
  echo "const int table[] = {"; for i in $(seq 90); do echo "  $i,"; done; echo "};"
  echo "}  // namespace a"
} > "$work/src/file.cpp"
if out=$(/usr/bin/python3 "$checker" "$work"); then echo "checker passed long functions:"; echo "$out"; exit 1; fi
for want in "tooLong is 81 lines" "member is" "3 function(s) over 80"; do
  grep -q "$want" <<<"$out" || { echo "missing: $want"; echo "$out"; exit 1; }
done
if grep -q " ok is" <<<"$out"; then echo "an 80-line function was flagged"; echo "$out"; exit 1; fi
echo "check_function_length self-test: the three long ones flagged, the 80-line one passed"
