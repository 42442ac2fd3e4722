# shellcheck shell=bash
# SPDX-License-Identifier: Apache-2.0
# Sourced by power-cut.sh (which sets cuts, out and log): where each cut landed, what the next boot found, the tally.
#   note_cut I DELAY_US MARKS     the console marks of the boot cut as cut I
#   judge I MARKS                 the next boot's verify lines: cut I's outcome
#   summary SECONDS FSCK          prints the tally; exits 0 when nothing failed
# A cut is judged against the last record whose save returned (acked) and the one
# in flight: "old" and "new" are the only good outcomes.

declare -A pc_mark=() pc_acked=() pc_flight=() pc_delay=()
declare -A pc_count=()
pc_failed=0
pc_phases=(BEGIN FSYNC SYNCED RENAME RENAMED DIRSYNC DIRSYNCED ACK)
declare -A pc_phase_text=(
  [BEGIN]="writing the temporary" [FSYNC]="in the temporary's fsync"
  [SYNCED]="temporary synced, not renamed" [RENAME]="in rename()"
  [RENAMED]="renamed, directory not synced" [DIRSYNC]="in the directory's fsync"
  [DIRSYNCED]="directory synced, save returning" [ACK]="save returned (acknowledged)")

note_cut() {
  local i="$1" last v
  last="$(grep -E '^PC (BEGIN|FSYNC|SYNCED|RENAME|RENAMED|DIRSYNC|DIRSYNCED|ACK) ' <<<"$3" | tail -n1)"
  grep -q '^PC SAVEFAILED' <<<"$3" && log "cut $i: a save failed: $(grep '^PC SAVEFAILED' <<<"$3" | head -n1)"
  read -r _ "pc_mark[$i]" v <<<"$last"
  pc_delay[$i]=$(($2 / 1000))
  if [[ "${pc_mark[$i]}" == ACK ]]; then
    pc_acked[$i]=$v; pc_flight[$i]="-"   # the next save has not begun: only v is right
  else
    pc_acked[$i]=$((v - 1)); pc_flight[$i]=$v
  fi
}

judge() {
  local i="$1" rec version whole outcome bad
  rec="$(grep '^PC RECORD' <<<"$2" | tail -n1)"
  version="$(sed -n 's/.* version=\([0-9]*\).*/\1/p' <<<"$rec")"
  whole="$(sed -n 's/.* whole=\([01]\).*/\1/p' <<<"$rec")"
  # A slot FileStorage refuses, or one whose content is not its record, breaks the
  # storage's own promise even when the other slot saves the end cap.
  bad="$(grep '^PC SLOT' <<<"$2" | grep -vE ' (ok .*whole=1|missing)( |$)' | sed 's/^PC SLOT //' | paste -sd ';' - || true)"
  if [[ -z "$version" ]]; then outcome=missing
  elif [[ "$whole" != 1 ]]; then outcome=mixed
  elif [[ "$version" == "${pc_flight[$i]}" ]]; then outcome=new
  elif [[ "$version" == "${pc_acked[$i]}" ]]; then outcome=old
  elif ((version < pc_acked[$i])); then outcome=lost
  else outcome=unexpected
  fi
  pc_count[$outcome]=$((${pc_count[$outcome]:-0} + 1))
  pc_count["${pc_mark[$i]}:$outcome"]=$((${pc_count["${pc_mark[$i]}:$outcome"]:-0} + 1))
  [[ -n "$bad" ]] && pc_count[bad_slots]=$((${pc_count[bad_slots]:-0} + 1))
  if [[ "$outcome" != old && "$outcome" != new ]] || [[ -n "$bad" ]]; then
    pc_failed=$((pc_failed + 1))
    log "cut $i (${pc_mark[$i]}, acked ${pc_acked[$i]}, in flight ${pc_flight[$i]}): $outcome, found '${rec#PC RECORD }'${bad:+, bad slots: $bad}"
  fi
  printf '%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\n' "$i" "${pc_delay[$i]}" "${pc_mark[$i]}" "${pc_acked[$i]}" \
    "${pc_flight[$i]}" "${version:-none}" "${whole:--}" "$outcome" "${bad:-ok}" >>"$out/cuts.tsv"
}

summary() {
  local p o n before=0 during=0 after=0 line
  echo "power-cut: where the $cuts cuts landed, and what the next boot found:"
  for p in "${pc_phases[@]}"; do
    n=0; line=""
    for o in old new lost mixed missing unexpected; do
      [[ -n "${pc_count[$p:$o]:-}" ]] && { line+=" $o ${pc_count[$p:$o]}"; n=$((n + ${pc_count[$p:$o]})); }
    done
    printf '  %-34s %4d %s\n' "${pc_phase_text[$p]}" "$n" "${line:+(${line# })}"
    case "$p" in BEGIN | FSYNC | SYNCED) before=$((before + n)) ;; RENAME) during=$((during + n)) ;;
      *) after=$((after + n)) ;; esac
  done
  echo "  before the rename $before, during it $during, after it $after"
  line=""
  for o in old new lost mixed missing unexpected; do line+=" $o ${pc_count[$o]:-0},"; done
  echo "  outcomes:${line%,}; slots failing FileStorage's check after ${pc_count[bad_slots]:-0} cut(s)"
  echo "  file system after the last boot (e2fsck -fn): $2; boots retried (the kernel died before the store): $pc_retries; $1 s"
  if ((pc_failed > 0)); then
    echo "power-cut: FAILED: $pc_failed of $cuts cuts did not leave a whole old or new record (${out}/cuts.tsv)"
    return 1
  fi
  echo "power-cut: OK: $cuts of $cuts cuts left a whole record (old or new)"
}
