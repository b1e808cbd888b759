#!/usr/bin/env bash
# Keeps scripts/packages.txt true: every library on the link lines of a configured build comes
# from a Debian package that scripts/packages.txt names, or that one of them pulls in through
# Depends/Pre-Depends (Recommends do not count: apt may be set not to install them).
#
#   scripts/check-packages.sh [BUILD_DIR [PACKAGES_TXT]]     (defaults: build, scripts/packages.txt)
#   CLAYFORM_PACKAGES=FILE scripts/check-packages.sh BUILD_DIR
#   CLAYFORM_PACKAGES_WITHOUT="pkg ..." ...   as if those lines were not in the list (to show the
#                                              check fails: tests/CMakeLists.txt drops libfontconfig-dev)
#
# How: reads LINK_LIBRARIES of every link step in BUILD_DIR/build.ninja; resolves each -lNAME to
# the file the linker uses (the compiler's -print-file-name, libNAME.so before libNAME.a) and
# keeps each absolute path outside the source and build trees; asks dpkg which package owns the
# file (following symlinks one hop at a time, so /usr/lib/.../libfoo.so is charged to the -dev
# package that ships the symlink, and an alternatives link to the package behind it); computes
# the Depends closure of the listed packages over what dpkg has installed. Prints one line per
# library and exits 1 naming every library whose package is not covered (2: usage/setup error).
set -euo pipefail

ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
BUILD=${1:-build}
LIST=${2:-${CLAYFORM_PACKAGES:-$ROOT/scripts/packages.txt}}

die() { echo "check-packages: $*" >&2; exit 2; }
[[ -f "$BUILD/build.ninja" ]] || die "$BUILD/build.ninja not found (give a build dir configured with -G Ninja)"
[[ -f "$LIST" ]] || die "package list $LIST not found"
command -v dpkg-query >/dev/null || die "dpkg-query not found: this check is for Debian"
BUILD=$(cd "$BUILD" && pwd)

# The compiler CMake uses answers where the linker finds -lNAME (its search dirs are the linker's).
cxx=$(sed -n 's/^CMAKE_CXX_COMPILER:[A-Z]*=//p' "$BUILD/CMakeCache.txt" 2>/dev/null | head -n1)
if [[ -z "$cxx" || ! -x "$cxx" ]]; then cxx=$(command -v c++ || command -v g++ || command -v gcc || true); fi
[[ -n "$cxx" ]] || die "no C++ compiler found to resolve -l flags"

# ---- 1. the libraries on our link lines ------------------------------------------------------
ninja_files=("$BUILD/build.ninja")
for f in "$BUILD"/CMakeFiles/impl-*.ninja; do [[ -f "$f" ]] && ninja_files+=("$f"); done
mapfile -t items < <(sed -n 's/^ *LINK_\(LIBRARIES\|FLAGS\) = //p' "${ninja_files[@]}" | tr ' ' '\n' |
  awk -v b="$BUILD/" -v s="$ROOT/" '
    /^-l./ { print; next }
    /^\// && /\.(so(\.[0-9.]+)?|a)$/ && index($0, b) != 1 && index($0, s) != 1 { print }' | sort -u)
((${#items[@]} > 0)) || die "no link libraries found in $BUILD/build.ninja (is it a CMake Ninja build dir?)"

# ---- 2. the file the linker uses for each ----------------------------------------------------
declare -A file_of=()
libs=()
for it in "${items[@]}"; do
  f=""
  if [[ "$it" == -l:* ]]; then
    f=$("$cxx" -print-file-name="${it#-l:}")
  elif [[ "$it" == -l* ]]; then
    for ext in so a; do
      f=$("$cxx" -print-file-name="lib${it#-l}.$ext")
      [[ "$f" == /* ]] && break
    done
  else
    f=$it
  fi
  if [[ "$f" == /* && -e "$f" ]]; then f=$(realpath -s "$f"); else f="(not found)"; fi
  file_of[$it]=$f
  libs+=("$it")
done

# Candidate paths for dpkg: the file, then each symlink hop; each also under /lib <-> /usr/lib
# (merged /usr: dpkg knows a file only under the path its package ships).
declare -A chain_of=()
all_paths=()
for it in "${libs[@]}"; do
  f=${file_of[$it]}
  [[ "$f" == /* ]] || continue
  chain=()
  for ((hop = 0; hop < 10; hop++)); do
    chain+=("$f")
    case "$f" in
      /usr/lib/*) chain+=("${f#/usr}") ;;
      /lib/*) chain+=("/usr$f") ;;
    esac
    [[ -L "$f" ]] || break
    t=$(readlink "$f")
    [[ "$t" == /* ]] || t="$(dirname "$f")/$t"
    f=$(realpath -s "$t")
  done
  chain_of[$it]="${chain[*]}"
  all_paths+=("${chain[@]}")
done

declare -A owner_of=()
if ((${#all_paths[@]} > 0)); then
  while IFS= read -r line; do
    [[ "$line" == diversion* ]] && continue
    path=${line##*: }
    pkgs=${line%: *}
    owners=""
    IFS=',' read -ra ps <<<"$pkgs"
    for p in "${ps[@]}"; do
      p=${p// /}
      owners+="${owners:+,}${p%%:*}"
    done
    owner_of[$path]=$owners
  done < <(dpkg-query -S "${all_paths[@]}" 2>/dev/null || true)
fi

# ---- 3. the listed packages and everything they pull in --------------------------------------
listed=()
without=" ${CLAYFORM_PACKAGES_WITHOUT:-} "
while read -r p _; do
  [[ -z "$p" || "$p" == \#* || "$without" == *" $p "* ]] && continue
  listed+=("$p")
done <"$LIST"
((${#listed[@]} > 0)) || die "no packages listed in $LIST"

# package -> the listed package that pulls it in (itself when listed), over installed packages.
declare -A via=()
while read -r pkg root; do
  [[ -n "${via[$pkg]:-}" ]] || via[$pkg]=$root
done < <(
  { printf 'LISTED\t%s\n' "${listed[@]}"
    dpkg-query -W -f='${db:Status-Abbrev}\t${Package}\t${Provides}\t${Pre-Depends}, ${Depends}\n' 2>/dev/null |
      awk -F'\t' '$1 ~ /^ii/ { print "PKG\t" $2 "\t" $3 "\t" $4 }'
  } | awk -F'\t' '
    function bare(x) { gsub(/\([^)]*\)/, "", x); gsub(/\[[^]]*\]/, "", x); gsub(/<[^>]*>/, "", x);
                       gsub(/[ \t]/, "", x); sub(/:.*/, "", x); return x }
    $1 == "LISTED" { order[++n] = $2; next }
    $1 == "PKG" {
      p = $2; inst[p] = 1
      m = split($3, pv, ","); for (i = 1; i <= m; i++) { v = bare(pv[i]); if (v != "") prov[v] = prov[v] " " p }
      deps[p] = deps[p] "," $4
    }
    END {
      for (i = 1; i <= n; i++) {
        r = order[i]; if (!(r in inst)) continue
        if (!(r in seen)) { seen[r] = r; q[++qt] = r }
      }
      # breadth first from all listed packages at once, in list order: each package is charged
      # to the first listed package that reaches it.
      for (qh = 1; qh <= qt; qh++) {
        p = q[qh]
        m = split(deps[p], groups, ",")
        for (g = 1; g <= m; g++) {
          k = split(groups[g], alts, "|")
          for (a = 1; a <= k; a++) {
            d = bare(alts[a]); if (d == "") continue
            cands = (d in inst ? d : "") " " (d in prov ? prov[d] : "")
            c = split(cands, cs, " ")
            for (j = 1; j <= c; j++) if (cs[j] != "" && !(cs[j] in seen)) { seen[cs[j]] = seen[p]; q[++qt] = cs[j] }
          }
        }
      }
      for (p in seen) print p "\t" seen[p]
    }')

not_installed=()
for p in "${listed[@]}"; do [[ -n "${via[$p]:-}" ]] || not_installed+=("$p"); done

# ---- 4. report ---------------------------------------------------------------------------------
bad=()
printf '%-28s %-58s %-32s %s\n' "library" "file" "package" "covered"
for it in "${libs[@]}"; do
  f=${file_of[$it]}
  pkg=""
  for c in ${chain_of[$it]:-}; do
    if [[ -n "${owner_of[$c]:-}" ]]; then pkg=${owner_of[$c]}; break; fi
  done
  status=""
  if [[ "$f" != /* ]]; then
    status="MISSING: the linker finds no file"
  elif [[ -z "$pkg" ]]; then
    status="MISSING: no Debian package owns it"
  else
    IFS=',' read -ra owners <<<"$pkg"
    for o in "${owners[@]}"; do
      r=${via[$o]:-}
      if [[ -n "$r" ]]; then
        if [[ "$r" == "$o" ]]; then status="listed"; else status="pulled in by $r"; fi
        pkg=$o
        break
      fi
    done
    [[ -n "$status" ]] || status="MISSING: add $pkg to $(basename "$LIST")"
  fi
  [[ "$status" == MISSING* ]] && bad+=("$it ($pkg)")
  printf '%-28s %-58s %-32s %s\n' "${it##*/}" "$f" "${pkg:--}" "$status"
done

if ((${#not_installed[@]} > 0)); then
  echo "note: listed but not installed here (their dependencies are not counted): ${not_installed[*]}"
fi
if ((${#bad[@]} > 0)); then
  echo "FAIL: ${#bad[@]} linked librar$( ((${#bad[@]} == 1)) && echo y || echo ies) not covered by $LIST: ${bad[*]}"
  exit 1
fi
echo "OK: all ${#libs[@]} libraries on the link lines come from packages named in $LIST or pulled in by them"
