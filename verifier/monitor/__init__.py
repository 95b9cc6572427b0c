"""The verifier's rules on a real line: `uitamr monitor` (live) and `uitamr replay` (a capture).

Data flow, pure in the middle and I/O at the edges:

    sources (serial port / TCP stream / capture file)  ->  Chunk(t_us, bytes)
    framer   (t3.5 silence + the protocol's frame lengths + CRC)  ->  frames
    classify (request or reply: content, then the master/slave turn)  ->  TraceRecord
    session  (the rules of `uitamr verify`, judging what the line settled)  ->  ScenarioResult
    reports  (the JSON, JUnit, JSONL trace and HTML writers of `uitamr verify`)
"""
