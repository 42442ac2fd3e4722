# SPDX-License-Identifier: Apache-2.0
"""What the scripts in tools/ share: finding and running the `tensegrity` program
(`program`), reading the records its runs write (`runs`), robot files changed for one
run (`robot_file`), and the helpers of the experiment scripts (`arm_keep`, `arm_stats`,
`experiment_pins`, `sweep_figure`, `experiment_figures`).

The scripts import it as `tensegrity_tools` (Python puts a script's own folder, tools/,
on the import path); no script imports another script.
"""
