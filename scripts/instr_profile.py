#!/usr/bin/env python3
"""The analysis half of scripts/instr-profile.sh: reads a callgrind output written with
--dump-instr=yes and prints, per traced ray, the instructions and simulated mispredicted branches,
the source lines that account for most instructions, and llvm-mca's cycle estimate of the path
every ray runs.

    instr_profile.py CALLGRIND_OUT BINARY RAYS_TRACED [MCA_CPU]
"""
import collections
import re
import shutil
import subprocess
import sys


def step(tok, cur):
    """A callgrind position: absolute, relative to the last (+n, -n), or the same (*)."""
    if tok == "*":
        return cur
    if tok[0] in "+-":
        return cur + int(tok)
    return int(tok, 0)


def per_instruction(path):
    """Ir and Bcm per instruction address, and (file, line) per address, from a callgrind file
    with `positions: instr line` (addresses and lines may be relative: +n, -n, or * for same)."""
    events = None
    files = {}
    ir, bcm, where = collections.Counter(), collections.Counter(), {}
    fl = None
    addr = line = 0
    skip_call_cost = False
    for raw in open(path):
        s = raw.rstrip("\n")
        if s.startswith("events:"):
            events = s.split()[1:]
            continue
        m = re.match(r"^(fl|fi|fe)=\((\d+)\)(?: (.*))?$", s)
        if m:
            if m.group(3):
                files[m.group(2)] = m.group(3)
            fl = files.get(m.group(2), fl)
            continue
        if s.startswith("calls="):
            skip_call_cost = True
            continue
        if not s or s[0] not in "0123456789+-*":
            continue
        parts = s.split()
        if len(parts) < 2:
            continue

        addr, line = step(parts[0], addr), step(parts[1], line)
        if skip_call_cost:
            skip_call_cost = False
            continue
        costs = dict(zip(events, (int(x) for x in parts[2:])))
        ir[addr] += costs.get("Ir", 0)
        bcm[addr] += costs.get("Bcm", 0) + costs.get("Bim", 0)
        where[addr] = (fl or "?", line)
    return ir, bcm, where


def main():
    out, binary, rays = sys.argv[1], sys.argv[2], int(sys.argv[3])
    mca_cpu = sys.argv[4] if len(sys.argv) > 4 else "znver3"
    ir, bcm, where = per_instruction(out)
    if rays <= 0 or not ir:
        sys.exit("instr-profile: nothing was counted")
    print(f"instructions per ray: {sum(ir.values()) / rays:.1f}")
    print(f"mispredicted branches per ray (callgrind's model): {sum(bcm.values()) / rays:.3f}")
    lines = collections.Counter()
    for a, n in ir.items():
        f, l = where[a]
        lines[f"{f.split('/')[-1]}:{l}"] += n
    print("source lines, instructions per ray:")
    for k, n in lines.most_common(20):
        print(f"  {n / rays:7.1f}  {k}")
    hot = sorted(a for a, n in ir.items() if n >= 0.9 * rays)
    if not hot or not shutil.which("llvm-mca") or not shutil.which("objdump"):
        return
    asm = subprocess.run(
        ["objdump", "-d", "--no-show-raw-insn", f"--start-address={hot[0]:#x}", f"--stop-address={hot[-1] + 16:#x}", binary],
        capture_output=True,
        text=True,
    ).stdout
    wanted, body = set(hot), []
    for l in asm.splitlines():
        m = re.match(r"^\s+([0-9a-f]+):\s+(\S.*)$", l)
        if not m or int(m.group(1), 16) not in wanted:
            continue
        ins = m.group(2).split("#")[0].strip()
        # Jumps and calls: llvm-mca models a straight path (and would need their targets as labels).
        if ins.startswith(("j", "call", "ret")) or "<" in ins:
            continue
        body.append(ins)
    mca = subprocess.run(
        ["llvm-mca", f"-mcpu={mca_cpu}", "-iterations=200"], input="\n".join(body) + "\n", capture_output=True, text=True
    ).stdout
    cycles = re.search(r"Total Cycles:\s+(\d+)", mca)
    rthr = re.search(r"Block RThroughput:\s+([\d.]+)", mca)
    if cycles:
        print(
            f"path every ray runs: {len(body)} instructions (no jumps); llvm-mca ({mca_cpu}): "
            f"{int(cycles.group(1)) / 200:.0f} cycles per ray, {float(rthr.group(1)):.0f} by the pipes' throughput alone"
        )


if __name__ == "__main__":
    main()
