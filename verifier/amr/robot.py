"""The emulated UITAMR robot: a deterministic state machine on a virtual clock.

Time is integer microseconds since power-on and only moves forward, through
:meth:`Robot.advance` or :meth:`Robot.on_request`; nothing sleeps. Given the same settings,
config, faults and requests at the same times, the robot answers the same bytes.

Modes: ``idle``; ``running`` (a point/script run, a tape command or a relative move);
``paused`` (01/80 during a task: the motion halts and keeps its remaining time; sending
the same point again resumes it, 01/A0 abandons it); ``manual`` (01/E0; code 05 moves
until 05/00; 01/A0 or any task command leaves manual mode).

Requests follow the Modbus serial-line rules (MODBUS over Serial Line V1.02 §2.4.1 and
Modbus Application Protocol V1.1b3 §7): a bad CRC or another slave's address gets no
reply; broadcast (address 0) control commands are carried out without a reply; an
unknown function code gets exception 01; a bad query parameter 02; an illegal value
(unknown control code or command, quantity other than 22, value field not 0) 03. The
frame rules themselves live in ``verifier.protocol`` (``decode_request`` says which
exception a bad request deserves); this module only decides what the robot does.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

from verifier.amr import motion as motions
from verifier.amr.config import RobotConfig
from verifier.amr.faults import Fault, check_fault_addresses
from verifier.amr.motion import MAGNETIC, TRACKLESS, Motion
from verifier.protocol.catalogue import (
    FC_READ_COILS,
    FC_WRITE_SINGLE_REGISTER,
    MOVE_CODES,
    POINT_NUMBERS,
    ControlCode,
    ManualMove,
    Query,
    RobotCommand,
    RobotError,
    command_title,
)
from verifier.protocol.codec import (
    decode_request,
    encode,
    exception_reply_for,
    hex_bytes,
    is_stop_command,
)
from verifier.protocol.crc import crc_ok, with_crc
from verifier.protocol.frames import (
    ControlReply,
    ControlRequest,
    ExceptionReply,
    FrameError,
    StatusReply,
    StatusRequest,
)
from verifier.protocol.settings import DEFAULT_SETTINGS, Settings
from verifier.protocol.timing import MIN_PERIOD_US, frame_time_us

TAPE_COMMANDS = frozenset({
    RobotCommand.SEEK_FORWARD, RobotCommand.SEEK_BACKWARD,
    RobotCommand.FOLLOW_FORWARD, RobotCommand.FOLLOW_BACKWARD,
    RobotCommand.FOLLOW_LEFT, RobotCommand.FOLLOW_RIGHT,
    RobotCommand.ROTATE_LEFT, RobotCommand.ROTATE_RIGHT,
})
MODES = ("idle", "running", "paused", "manual")
REQUEST_KINDS = {FC_WRITE_SINGLE_REGISTER: "control", FC_READ_COILS: "status"}  # as faults name them


@dataclass(frozen=True)
class Reply:
    """What the robot sends back: ``data`` starting ``delay_us`` after the request's end.

    ``delay_us`` is the turnaround plus any scripted lateness; the line never starts a
    reply before t3.5 of silence has ended the request. ``note`` lists the faults applied.
    """

    data: bytes
    delay_us: int
    note: str = ""


@dataclass(frozen=True)
class RobotEvent:
    """Something the robot did or refused, for logs and for the verifier's report."""

    t_us: int
    kind: str
    message: str


@dataclass
class _Condition:
    """An active error condition from a state fault."""

    error: RobotError
    until_us: int | None  # None: until the stop command (or for ever, for the battery)
    source: str


@dataclass
class _FaultState:
    fault: Fault
    index: int
    start_us: int | None = None
    hits: int = 0
    done: bool = False
    no_effect: str | None = None  # a state fault that struck and changed nothing: why


def _when(fault: Fault, t_us: int) -> str:
    """When a fault struck, for a fault triggered by a request number (one at `at_s` says so)."""
    return "" if fault.at_us is not None else f" at {t_us / 1e6:g} s"


@dataclass
class _Pending:
    """Reply-fault bookkeeping for one request."""

    faults: list[Fault] = field(default_factory=list)

    def has(self, kind: str) -> Fault | None:
        for fault in self.faults:
            if fault.kind == kind:
                return fault
        return None


class Robot:
    """The robot model; see the module docstring for its behaviour."""

    def __init__(self, settings: Settings = DEFAULT_SETTINGS, config: RobotConfig | None = None,
                 faults: list[Fault] | tuple[Fault, ...] = ()) -> None:
        check_fault_addresses(faults, settings.address)
        self.settings = settings
        self.config = config if config is not None else RobotConfig()
        self.now_us = 0
        self.mode = "idle"
        self.motion: Motion | None = None
        self._pose = self.config.start_pose
        self.battery_pct = self.config.battery_pct
        self._drain = (0, self.battery_pct, self.config.battery_drain_idle_pct_per_min)  # (since µs, % then, %/min)
        self.speed_stage = self.config.speed_stage
        self.magnetic_speed_stage = self.config.magnetic_speed_stage
        self.collision_range_stage = self.config.collision_range_stage
        self.stop_seen = False
        self.requests = 0
        self.events: list[RobotEvent] = []
        self._drive = TRACKLESS
        self._point: int | None = None
        self._conditions: dict[int, _Condition] = {}
        self._last_start_us: int | None = None  # the previous request's start (pacing "late": its answer's)
        self._previous_start_us: int | None = None  # when the previous request really started
        self._state_faults = [_FaultState(f, i) for i, f in enumerate(faults) if f.is_state_fault]
        self._reply_faults = [_FaultState(f, i) for i, f in enumerate(faults) if not f.is_state_fault]
        self._battery_was_low = self.battery_low
        self._decoded: dict[bytes, ControlRequest | StatusRequest] = {}
        self._encoded: dict[ControlReply | StatusReply, bytes] = {}
        self._status_replies: dict[tuple, bytes] = {}  # (address, error, value, query) -> bytes

    # ---- what the robot reports ---------------------------------------------------------

    @property
    def pose(self) -> tuple[float, float, float]:
        """(x_m, y_m, heading_rad) now."""
        return self.motion.pose() if self.motion is not None else self._pose

    @property
    def battery_low(self) -> bool:
        if not self._conditions:  # no scripted fault active (the usual case): the charge alone
            return self.battery_pct <= self.config.battery_low_pct
        forced = any(c.error == RobotError.BATTERY_LOW for c in self._conditions.values())
        return forced or self.battery_pct <= self.config.battery_low_pct

    @property
    def error(self) -> RobotError:
        """The error byte: the most urgent active error (01 before 02 before 03), or 00."""
        if not self._conditions:  # no scripted fault active: only the charge can raise one
            return RobotError.BATTERY_LOW if self.battery_pct <= self.config.battery_low_pct else RobotError.NONE
        active = {c.error for c in self._conditions.values()}
        if self.battery_low:
            active.add(RobotError.BATTERY_LOW)
        return min(active) if active else RobotError.NONE

    @property
    def task_running(self) -> bool:
        """Task status 1: a task runs or is paused, or a manual move is under way."""
        return self.mode in ("running", "paused") or (self.mode == "manual" and self.motion is not None)

    def status_value(self, query: Query) -> int:
        if query == Query.TASK:
            return int(self.task_running)
        if query == Query.VEHICLE:
            return int(self.error)
        if query == Query.SPEED:
            return self.magnetic_speed_stage if self._drive == MAGNETIC else self.speed_stage
        return int(self.battery_low)

    def snapshot(self) -> dict:
        """The robot's state in plain values (for logs and tests)."""
        x, y, h = self.pose
        return {
            "t_s": self.now_us / 1e6, "mode": self.mode,
            "task": self.motion.title if self.motion else None,
            "x_m": round(x, 6), "y_m": round(y, 6), "heading_rad": round(h, 6),
            "battery_pct": round(self.battery_pct, 6), "battery_low": self.battery_low,
            "error": int(self.error), "speed_stage": self.speed_stage,
            "magnetic_speed_stage": self.magnetic_speed_stage,
            "collision_range_stage": self.collision_range_stage, "stop_seen": self.stop_seen,
            "requests": self.requests,
        }

    def reply_faults_missed(self) -> list[tuple[int, Fault]]:
        """The reply faults (index in the fault list, fault) that no request met: their
        window passed, or their request never came, with nothing to disturb. A run that
        lists one here did not test that fault at all."""
        return [(state.index, state.fault) for state in self._reply_faults if state.hits == 0]

    def state_faults_without_effect(self) -> list[tuple[int, Fault, str]]:
        """The state faults (index, fault, why) that struck and changed nothing: an
        ``off_tape`` while no magnetic-tape task ran, an ``anti_collision`` while the
        anti-collision range was 0 m. Like a reply fault no request met, it tested nothing."""
        return [(state.index, state.fault, state.no_effect) for state in self._state_faults
                if state.no_effect is not None]

    # ---- time ----------------------------------------------------------------------------

    def advance(self, t_us: int) -> None:
        """Run the robot up to ``t_us``: tasks finish, scripted faults start and end."""
        if t_us < self.now_us:
            raise ValueError(f"robot time cannot go back: {t_us} µs < {self.now_us} µs")
        while (due := self._next_due_us()) is not None and due <= t_us:
            self._run_until(due)
            self._fire_due()
        self._run_until(t_us)

    def _next_due_us(self) -> int | None:
        """The next time something happens by itself: a task ends, a timed fault starts
        or ends (None: nothing is due)."""
        due = None
        if self.mode == "running" and self.motion is not None and self.motion.remaining_us is not None:
            due = self.now_us + self.motion.remaining_us
        for state in self._state_faults:
            if state.start_us is None and state.fault.at_us is not None:
                due = state.fault.at_us if due is None else min(due, state.fault.at_us)
        for cond in self._conditions.values():
            if cond.until_us is not None:
                due = cond.until_us if due is None else min(due, cond.until_us)
        return due

    def _moving(self) -> bool:
        return self.motion is not None and self.mode in ("running", "manual")

    def _run_until(self, t_us: int) -> None:
        dt = t_us - self.now_us
        if dt <= 0:
            return
        moving = self._moving()
        if moving:
            self.motion.elapsed_us += dt
        per_min = (self.config.battery_drain_running_pct_per_min if moving
                   else self.config.battery_drain_idle_pct_per_min)
        # The charge is a function of time since the drain rate last changed, not a sum of
        # steps: the same at any t whether the clock got there in one step or in many.
        t0, pct0, rate = self._drain
        if rate != per_min:
            t0, pct0, rate = self._drain = (self.now_us, self.battery_pct, per_min)
        before = self.battery_pct
        self.battery_pct = max(0.0, pct0 - rate * (t_us - t0) / 60_000_000)
        low = self.config.battery_low_pct
        if before > low >= self.battery_pct and per_min > 0:
            crossing = t0 + round((pct0 - low) / rate * 60_000_000)
            self._log(min(crossing, t_us), "battery",
                      f"battery at {low:g} %: battery query answers 1, error 03")
        self.now_us = t_us

    def _fire_due(self) -> None:
        t = self.now_us
        if self.mode == "running" and self.motion is not None and self.motion.remaining_us == 0:
            self._pose = self.motion.pose()
            self._log(t, "task", f"{self.motion.title}: done")
            self.motion, self.mode, self._point = None, "idle", None
        for state in self._state_faults:
            if state.start_us is None and state.fault.at_us is not None and state.fault.at_us <= t:
                self._start_state_fault(state, t)
        for key, cond in list(self._conditions.items()):
            if cond.until_us is not None and cond.until_us <= t:
                del self._conditions[key]
                self._log(t, "fault", f"{cond.source}: over (error {int(cond.error):02d} clears)")

    # ---- requests ------------------------------------------------------------------------

    def on_request(self, frame: bytes, t_us: int, start_us: int | None = None) -> Reply | None:
        """Handle one complete request frame that ended at ``t_us``; None = no reply.

        ``start_us`` is when its first byte started (default: ``t_us`` minus the frame's
        time on the line); pacing is judged from starts.
        """
        frame = bytes(frame)
        self.advance(t_us)
        if frame not in self._decoded and (len(frame) < 4 or not crc_ok(frame)):  # decoded: CRC ok
            self._log(t_us, "silent", f"bad CRC or too short ({hex_bytes(frame)}): no reply")
            return None
        address, function = frame[0], frame[1]
        if address == 0:
            self._broadcast(frame, t_us)
            return None
        if address != self.settings.address:
            self._log(t_us, "silent", f"request for address {address}, not {self.settings.address}: no reply")
            return None
        self.requests += 1
        number = self.requests
        start = start_us if start_us is not None else t_us - frame_time_us(len(frame))
        kind = REQUEST_KINDS.get(function, "other")
        pacing_delay = self._pacing(start, t_us, number)
        if pacing_delay is None:
            self._start_request_faults(number, t_us)
            return None
        pending = self._reply_faults_for(number, t_us, kind)
        if (fault := pending.has("no_reply")) is not None:
            self._start_request_faults(number, t_us)
            self._log(t_us, "fault", f"request {number}: {fault.describe()}: no reply, request lost")
            return None
        data = self._answer(frame, t_us, number, pending)
        if data is None:
            return None
        return self._disturb(data, pacing_delay, pending, number, t_us)

    def _pacing(self, start: int, t_us: int, number: int) -> int | None:
        """Extra delay for a request that breaks the 250 ms pacing, or None to ignore it."""
        last, previous = self._last_start_us, self._previous_start_us
        self._previous_start_us = start
        if last is None or start - last > MIN_PERIOD_US:
            self._last_start_us = start
            if previous is not None and start - previous <= MIN_PERIOD_US:
                # pacing "ignore": the requests it dropped do not count for the robot, but the
                # master still sent this one too soon after the previous, and the log said
                # nothing of it (a master at 100 ms: every third request went unmarked)
                self._log(t_us, "pacing", f"request {number} came {(start - previous) / 1000:.1f} ms after the "
                          "previous one (must be > 250 ms): answered, as more than 250 ms after the last one answered")
            return 0
        # the gap the master left, from the previous request (not from a late answer to it)
        gap_ms = (start - (previous if previous is not None else last)) / 1000
        policy = self.config.pacing
        if policy == "ignore":
            self._log(t_us, "pacing", f"request {number} came {gap_ms:.1f} ms after the previous one "
                      "(must be > 250 ms): ignored")
            return None
        if policy == "late":
            delay = last + MIN_PERIOD_US + 1 - start
            self._last_start_us = start + delay
            self._log(t_us, "pacing", f"request {number} came {gap_ms:.1f} ms after the previous one "
                      f"(must be > 250 ms): answered {delay / 1000:.1f} ms late")
            return delay
        self._last_start_us = start
        self._log(t_us, "pacing", f"request {number} came {gap_ms:.1f} ms after the previous one "
                  "(must be > 250 ms): answered normally")
        return 0

    def _answer(self, frame: bytes, t_us: int, number: int, pending: _Pending) -> bytes | None:
        """Carry out the request and build the normal (or exception) reply."""
        address, function = frame[0], frame[1]
        exception_fault = pending.has("exception")
        try:
            request = self._decode(frame)
        except FrameError as err:
            self._start_request_faults(number, t_us)
            answer = exception_reply_for(err, self.settings)
            if answer is None:
                self._log(t_us, "silent", f"request {number}: {err}: no reply")
                return None
            if exception_fault is not None:
                answer = ExceptionReply(address, function, exception_fault.code)
            code = int(answer.exception_code)
            self._log(t_us, "exception", f"request {number}: {err}: exception {code:02X}")
            return encode(answer, self.settings)
        if exception_fault is not None:
            self._start_request_faults(number, t_us)
            self._log(t_us, "fault", f"request {number}: {exception_fault.describe()}: "
                      "not carried out, exception reply")
            return encode(ExceptionReply(address, function, exception_fault.code), self.settings)
        if isinstance(request, ControlRequest):
            self._execute(request, t_us)
            self._start_request_faults(number, t_us)
            return self._encode(ControlReply.echo(request))
        assert isinstance(request, StatusRequest)
        self._start_request_faults(number, t_us)
        value = self.status_value(request.query)
        key = (address, self.error, value, request.query)
        data = self._status_replies.get(key)
        if data is None:
            data = self._status_replies[key] = self._encode(StatusReply(*key))
        return data

    def _decode(self, frame: bytes) -> ControlRequest | StatusRequest:
        """decode_request, remembered per frame: a master repeats the same few requests."""
        request = self._decoded.get(frame)
        if request is None:
            request = self._decoded[frame] = decode_request(frame, self.settings)
        return request

    def _encode(self, reply: ControlReply | StatusReply) -> bytes:
        """encode, remembered per reply (frames are frozen values)."""
        data = self._encoded.get(reply)
        if data is None:
            data = self._encoded[reply] = encode(reply, self.settings)
        return data

    def _disturb(self, data: bytes, extra_delay: int, pending: _Pending, number: int,
                 t_us: int) -> Reply:
        """Apply the reply faults that hit this request to the reply bytes."""
        if not pending.faults:
            return Reply(data, self.config.turnaround_us + extra_delay)
        notes = []
        if (fault := pending.has("wrong_address")) is not None:
            other = fault.address if fault.address is not None else self.settings.address % 247 + 1
            data = with_crc(bytes((other,)) + data[1:-2])
            notes.append(fault.describe())
        if (fault := pending.has("bad_crc")) is not None:
            data = data[:-2] + bytes(b ^ 0xFF for b in data[-2:])
            notes.append(fault.describe())
        if (fault := pending.has("garbage")) is not None:
            data = {"instead": fault.data, "before": fault.data + data,
                    "after": data + fault.data}[fault.position]
            notes.append(fault.describe())
        delay = self.config.turnaround_us + extra_delay
        if (fault := pending.has("late_reply")) is not None:
            delay += round(fault.delay_ms * 1000)
            notes.append(fault.describe())
        note = "; ".join(notes)
        if note:
            self._log(t_us, "fault", f"request {number}: {note}")
        return Reply(data, delay, note)

    def _broadcast(self, frame: bytes, t_us: int) -> None:
        try:
            request = decode_request(frame, self.settings)
        except FrameError as err:
            self._log(t_us, "silent", f"broadcast: {err}: ignored")
            return
        if isinstance(request, ControlRequest):
            self._log(t_us, "command", "broadcast control command: carried out, no reply")
            self._execute(request, t_us)
        else:
            self._log(t_us, "silent", "broadcast status request: no reply")

    # ---- faults --------------------------------------------------------------------------

    def _reply_faults_for(self, number: int, t_us: int, kind: str) -> _Pending:
        pending = _Pending()
        for state in self._reply_faults:
            fault = state.fault
            if fault.at_us is not None:
                if t_us < fault.at_us:
                    continue
                state.start_us = fault.at_us
            else:
                if number < fault.on_request:
                    continue
                if state.start_us is None:
                    state.start_us = t_us
            if fault.requests != "any" and fault.requests != kind:
                continue
            limit = fault.count if fault.count is not None else (None if fault.duration_us else 1)
            if limit is not None and state.hits >= limit:
                continue
            if fault.duration_us is not None and t_us >= state.start_us + fault.duration_us:
                continue
            state.hits += 1
            pending.faults.append(fault)
        return pending

    def _start_request_faults(self, number: int, t_us: int) -> None:
        for state in self._state_faults:
            if state.start_us is None and state.fault.on_request == number:
                self._start_state_fault(state, t_us)

    def _start_state_fault(self, state: _FaultState, t_us: int) -> None:
        fault = state.fault
        state.start_us = t_us
        until = None if fault.duration_us is None else t_us + fault.duration_us
        what = fault.describe()
        if fault.kind == "anti_collision":
            if self.collision_range_stage == 0:
                state.no_effect = f"the anti-collision range was 0 m (off) when it struck{_when(fault, t_us)}"
                self._log(t_us, "fault", f"{what}: no effect, anti-collision range is 0 m (off)")
                return
            self._conditions[state.index] = _Condition(RobotError.ANTI_COLLISION, until, what)
            self._log(t_us, "fault", f"{what}: error 01" + self._halt("anti-collision stop"))
        elif fault.kind == "off_tape":
            if self.motion is None or not self.motion.uses_tape or self.mode not in ("running", "paused"):
                state.no_effect = (f"no magnetic-tape task (seek, follow, rotate) was running when it "
                                   f"struck{_when(fault, t_us)}, and it has no effect otherwise")
                self._log(t_us, "fault", f"{what}: no effect, no magnetic-tape task running")
                return
            self._conditions[state.index] = _Condition(RobotError.OFF_TAPE, until, what)
            self._log(t_us, "fault", f"{what}: error 02" + self._halt("left the tape"))
        else:
            self._conditions[state.index] = _Condition(RobotError.BATTERY_LOW, until, what)
            self._log(t_us, "fault", f"{what}: battery query answers 1, error 03")

    def _halt(self, why: str) -> str:
        """Stop whatever moves (task or manual move); returns text for the log."""
        if self.motion is None:
            return ""
        title = self.motion.title
        self._pose = self.motion.pose()
        self.motion, self._point = None, None
        if self.mode in ("running", "paused"):
            self.mode = "idle"
        return f", {title} stopped ({why})"

    # ---- control commands ----------------------------------------------------------------

    def _execute(self, request: ControlRequest, t_us: int) -> None:
        code, command = request.code, request.command
        title = command_title(code, command)
        first_stop = is_stop_command(request, self.settings) and not self.stop_seen
        if is_stop_command(request, self.settings):
            self.stop_seen = True
        if code == ControlCode.ROBOT:
            self._robot_command(command, title, t_us, first_stop)
        elif code == ControlCode.SPEED_TRACKLESS:
            self.speed_stage = command
            self._log(t_us, "command", f"{title} (next moves)")
        elif code == ControlCode.SPEED_MAGNETIC:
            self.magnetic_speed_stage = command
            self._log(t_us, "command", f"{title} (next tape commands)")
        elif code == ControlCode.COLLISION_RANGE:
            self.collision_range_stage = command
            self._log(t_us, "command", title)
        elif code == ControlCode.MANUAL:
            self._manual_move(ManualMove(command), title, t_us, first_stop)
        elif code in MOVE_CODES:
            if self._may_move(title, t_us):
                stage = self.speed_stage
                self._start(motions.relative_move(code, command, self.pose, self.config, stage, title),
                            TRACKLESS, t_us)

    def _robot_command(self, command: int, title: str, t_us: int, first_stop: bool) -> None:
        if command == RobotCommand.STOP:
            latched = [k for k, c in self._conditions.items()
                       if c.until_us is None and c.error != RobotError.BATTERY_LOW]
            for key in latched:
                del self._conditions[key]
            halted = self._halt("stop command")
            was_manual = self.mode == "manual"
            self.mode = "idle"
            extra = " (the power-on stop)" if first_stop else ""
            cleared = ", latched errors cleared" if latched else ""
            self._log(t_us, "command", f"stop{extra}{halted}{', manual mode left' if was_manual else ''}{cleared}")
        elif command == RobotCommand.PAUSE:
            if self.mode == "running":
                self.mode = "paused"
                self._log(t_us, "command", f"pause: {self.motion.title} paused")
            else:
                self._log(t_us, "ignored", f"pause: nothing running ({self.mode})")
        elif command == RobotCommand.RESET:
            if self.motion is not None:
                self.motion = self._rebased(self.motion)
                self.motion.start = (0.0, 0.0, 0.0)
            self._pose = (0.0, 0.0, 0.0)
            self._log(t_us, "command", "coordinate reset: pose is now (0, 0, 0)")
        elif command == RobotCommand.MANUAL_MODE:
            if self._may_move(title, t_us, obstacle_blocks=False):
                halted = self._halt("manual mode")
                self.mode = "manual"
                self._log(t_us, "command", f"manual mode{halted}")
        elif command in TAPE_COMMANDS:
            if not self._may_move(title, t_us):
                return
            if any(c.error == RobotError.OFF_TAPE for c in self._conditions.values()):
                self._log(t_us, "ignored", f"{title}: refused, robot is off the tape (error 02)")
                return
            stage = self.magnetic_speed_stage
            self._start(motions.tape_motion(RobotCommand(command), self.pose, self.config, stage, title),
                        MAGNETIC, t_us)
        elif command in POINT_NUMBERS:
            self._point_command(command, title, t_us)

    def _point_command(self, point: int, title: str, t_us: int) -> None:
        if self.mode == "paused" and self._point == point:
            self.mode = "running"
            self._log(t_us, "command", f"{title}: resumed ({self.motion.remaining_us / 1e6:g} s left)")
            return
        if not self.config.is_taught(point):
            self._log(t_us, "ignored", f"{title}: point {point} is not taught, the robot stays "
                      "where it is (manual note 1)")
            return
        if self._may_move(title, t_us):
            self._start(motions.point_run(point, self.pose, self.config, title), TRACKLESS, t_us)
            self._point = point

    def _manual_move(self, move: ManualMove, title: str, t_us: int, first_stop: bool = False) -> None:
        """``first_stop``: this 05/00 is the power-on stop (``manual_stop_counts_as_stop``)."""
        if self.mode != "manual":
            if first_stop:
                self._log(t_us, "command", f"{title}: the power-on stop; not in manual mode, nothing to stop")
            else:
                self._log(t_us, "ignored", f"{title}: not in manual mode (send 01/E0 first)")
            return
        if move == ManualMove.STOP:
            halted = self._halt("manual stop")
            self._log(t_us, "command", f"manual stop{' (the power-on stop)' if first_stop else ''}{halted}")
            return
        if self._may_move(title, t_us):
            self._halt("next manual move")
            self.motion = motions.manual_motion(move, self.pose, self.config, title)
            self._log(t_us, "command", title)

    def _may_move(self, title: str, t_us: int, obstacle_blocks: bool = True) -> bool:
        if not self.stop_seen and self.config.before_stop == "ignore":
            self._log(t_us, "ignored", f"{title}: ignored, no stop command since power-on "
                      "(the first control command must be 01/A0)")
            return False
        if obstacle_blocks and any(c.error == RobotError.ANTI_COLLISION for c in self._conditions.values()):
            self._log(t_us, "ignored", f"{title}: refused, anti-collision active (error 01)")
            return False
        return True

    def _start(self, new: Motion, drive: str, t_us: int) -> None:
        replaced = f" (replaces {self.motion.title})" if self.motion is not None else ""
        if self.motion is not None:
            self._pose = self.motion.pose()
        new.start = self._pose
        self.motion, self.mode, self._drive, self._point = new, "running", drive, None
        duration = "" if new.duration_us is None else f", {new.duration_us / 1e6:g} s"
        self._log(t_us, "task", f"{new.title}: started{duration}{replaced}")

    @staticmethod
    def _rebased(old: Motion) -> Motion:
        """The rest of ``old`` as a fresh motion starting where the robot is now."""
        here = old.pose()
        if old.duration_us is None:
            return Motion(old.title, old.kind, here, old.delta, None, 0, old.world_frame)
        share = 0.0 if old.duration_us == 0 else 1 - min(1.0, old.elapsed_us / old.duration_us)
        rest = tuple(d * share for d in old.delta)
        if not old.world_frame:
            # Express the remaining displacement in the world frame so the new start
            # heading does not turn it.
            h = old.start[2]
            dx, dy = rest[0] * math.cos(h) - rest[1] * math.sin(h), rest[0] * math.sin(h) + rest[1] * math.cos(h)
            rest = (dx, dy, rest[2])
        return Motion(old.title, old.kind, here, rest, old.remaining_us, 0)  # type: ignore[arg-type]

    def _log(self, t_us: int, kind: str, message: str) -> None:
        self.events.append(RobotEvent(t_us, kind, message))
