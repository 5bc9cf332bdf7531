# Sourced by the benchmark scripts: fills the associative array BAGS (name -> bag) with the real logs
# found in $DATA (../shared/datasets), converting the text logs with log_to_bag into $OUT once (again
# only when the log is newer than its bag). Needs DATA, OUT and the sourced workspace.
_convert_log() {  # format input output
  [[ -f "$3" && "$3" -nt "$2" ]] || rosrun laser_dpslam log_to_bag --format "$1" "$2" "$3" > /dev/null
}
declare -gA BAGS
if [[ -f "$DATA/mit-csail/mit-csail.clf" ]]; then _convert_log carmen "$DATA/mit-csail/mit-csail.clf" "$OUT/mit-csail.bag"; BAGS[mit-csail]="$OUT/mit-csail.bag"; fi
for e in exp1 exp2; do
  if [[ -f "$DATA/urg04lx-mines/$e.dat" ]]; then _convert_log mines "$DATA/urg04lx-mines/$e.dat" "$OUT/mines-$e.bag"; BAGS[mines-$e]="$OUT/mines-$e.bag"; fi
done
if [[ -f "$DATA/dpslam-loop5/loop5.log" ]]; then _convert_log dpslam "$DATA/dpslam-loop5/loop5.log" "$OUT/loop5.bag"; BAGS[loop5]="$OUT/loop5.bag"; fi
if [[ -f "$DATA/scan_tools-demo/laser_scan_matcher_demo.bag" ]]; then BAGS[scan_tools-demo]="$DATA/scan_tools-demo/laser_scan_matcher_demo.bag"; fi
