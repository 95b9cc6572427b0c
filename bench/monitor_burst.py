"""`uitamr monitor` fed a burst: a TCP server on 127.0.0.1 writes 1 MB of valid Modbus RTU
request/reply frames at once (what a converter's buffer hands over after a hiccup), and
the monitor runs for --duration.

    python bench/monitor_burst.py [--mb 1] [--duration 20] [--quiet] [--root DIR]

Prints the wall time and the peak RSS (os.wait4) of the whole `uitamr monitor` process,
its exit status and the frame counts of its JSON report. --root runs the code of another
checkout (e.g. an export of an older commit) side by side.
"""
from __future__ import annotations

import argparse
import json
import os
import socket
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

#: the robot's power-on stop and its echo, then a status read and its reply: 32 bytes
EXCHANGES = bytes.fromhex("01 06 01 A0 00 00 88 14" "01 06 01 A0 00 00 88 14"
                          "01 01 00 00 00 16 BD C4" "01 01 03 00 00 00 3C 4E")


def serve(server: socket.socket, payload: bytes, done: threading.Event) -> None:
    connection, _ = server.accept()
    with connection:
        connection.sendall(payload)
        done.wait()  # keep the stream open: the monitor stops by --duration


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--mb", type=float, default=1.0)
    parser.add_argument("--duration", default="20s")
    parser.add_argument("--quiet", action="store_true")
    parser.add_argument("--root", type=Path, default=ROOT)
    args = parser.parse_args()
    size = int(args.mb * 1_000_000)
    payload = (EXCHANGES * (size // len(EXCHANGES) + 1))[:size]
    server = socket.create_server(("127.0.0.1", 0))
    done = threading.Event()
    thread = threading.Thread(target=serve, args=(server, payload, done), daemon=True)
    thread.start()
    with tempfile.TemporaryDirectory() as folder:
        report = Path(folder) / "m.json"
        command = [sys.executable, "-m", "verifier.cli", "monitor", "--tcp",
                   f"127.0.0.1:{server.getsockname()[1]}", "--duration", args.duration, "--json", str(report)]
        if args.quiet:
            command.append("--quiet")
        start = time.perf_counter()
        proc = subprocess.Popen(command, cwd=args.root, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
        _, status, usage = os.wait4(proc.pid, 0)
        wall = time.perf_counter() - start
        done.set()
        error = proc.stderr.read().decode()
        proc.stderr.close()
        frames = json.loads(report.read_text())["scenarios"][0]["frames"] if report.exists() else None
    server.close()
    print(f"{args.mb:g} MB burst, monitor --duration {args.duration}{' --quiet' if args.quiet else ''} "
          f"({args.root}): wall {wall:.1f} s, peak RSS {usage.ru_maxrss / 1024:.0f} MiB, "
          f"exit {os.waitstatus_to_exitcode(status)}, frames {frames}")
    if error.strip():
        print(error.strip()[-2000:])


if __name__ == "__main__":
    main()
