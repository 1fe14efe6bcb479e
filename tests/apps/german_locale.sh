#!/usr/bin/env bash
# INI numbers under a locale whose decimal point is a comma (de_DE.UTF-8,
# compiled here with localedef from Debian's locales data, so that no
# system locale is needed): the parser must not read "0.5" as 0.
set -euo pipefail
tests="$1"; work="$2"
mkdir -p "$work"
[ -d "$work/de_DE.UTF-8" ] || localedef -i de_DE -f UTF-8 "$work/de_DE.UTF-8" 2>/dev/null || true
[ -d "$work/de_DE.UTF-8" ] || { echo "localedef could not build de_DE.UTF-8 (package 'locales' missing?)"; exit 1; }
LOCPATH="$work" LC_ALL=de_DE.UTF-8 GSSM_EXPECT_COMMA_LOCALE=1 "$tests" --gtest_filter='IniLocale.*'
