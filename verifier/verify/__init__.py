"""`uitamr verify`: run PLC programs against the emulated robot and judge the traffic.

The pieces, each with one job:

- `durations`, `conditions` — the small languages of scenario files ("250ms",
  "o_bErr AND o_uErrId = 16#0101");
- `evidence` — what a run leaves behind (trace, line events, sampled PLC variables) and
  what a check reports (`Violation`);
- `traffic` — pairs each request the PLC sent with what came back;
- `rules` — the compliance rules, pure functions over the evidence;
- `expectations` — the scenario's expectations on PLC variables and on the traffic;
- `scenario` — loading and strict validation of scenario TOML files;
- `runner` — wires the simulated PLC, the virtual RS-485 line and the robot together;
- `result` — the outcome of one scenario, as every report reads it;
- `report_*` — console, JSON, JUnit XML, JSON Lines trace and HTML reports.
"""
