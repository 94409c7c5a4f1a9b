#!/usr/bin/python3
"""Mutated scenes: every one is refused with a message or runs.

From scenes/tiny.toml, COUNT scenes (fixed seed), each with one to three of the scene's
keys (as `sim_node - --resolved` lists them) set to hostile values (0, negatives, 2^31, 2^53 + 1, 2^62, 1e300,
1e-300, nan, inf, 1.0000000000000002, strings, booleans, arrays, tables)
or unknown keys and tables added. Each goes to `sim_node --check`:
refused means exit 2 with "invalid scene" (or "sim_node:") and the key
named; anything else (a signal, an exception's text, another code) fails.
An accepted scene runs (sim_node alone, on a private bus) for up to
RUN_SECONDS: it must end with exit 0, or still be running and making
progress (its status lines move), never crash or hang.

Usage: fuzz_scenes.py SIM_NODE ROOT [COUNT] (run inside a private network
namespace; tests/process_tests.cmake does it through netns.sh).
"""
import os
import random
import re
import subprocess
import sys
import tempfile
import tomllib



def scene_keys(sim):
    """Every table and key of a scene, as the simulator describes them (the
    default scene resolved: sim_node - --resolved), less the derived [model]."""
    r = subprocess.run([sim, "-", "--resolved"], input="", capture_output=True, text=True, check=True)
    return {t: sorted(keys) for t, keys in tomllib.loads(r.stdout).items() if t != "model" and isinstance(keys, dict)}


VALUES = ["0", "-1", "1", "2", "3", "7", "2147483648", "9007199254740993", "4611686018427387904", "1e300",
          "-1e300", "1e-300", "nan", "inf", "-inf", "0.5", "0.05", "3.7", "1.0000000000000002", "0.9999999999",
          '"x"', '"all"', '"tau_alpha"', '"g_ab"', "true", "false", "[]", "[1, 2]", "[0.5, 0.5]", '["overlap"]',
          "[1e300]", "[-1]", "{ a = 1 }", "100000", "1e9", "1e-9", "65001", "0.3", "0.8999"]
RUN_SECONDS = 6


def mutate(text, rng, keys):
    lines = text.split("\n")
    for _ in range(rng.randint(1, 3)):
        r = rng.random()
        if r < 0.06:
            lines.append(f"\n[{rng.choice(['sytem', 'extra', 'run'])}]\nbogus_key = 1")
            continue
        table = rng.choice(list(keys))
        key = rng.choice(keys[table])
        value = rng.choice(VALUES)
        # Half the time a plausible value: the current number scaled by up to
        # 10^3 either way (or a small integer), so that many scenes run.
        cur_value = re.search(rf"^\[{table}\][^\[]*?^{key}\s*=\s*([-0-9.e+]+)\s*(#.*)?$", "\n".join(lines),
                              re.M | re.S)
        if cur_value and rng.random() < 0.5:
            v = float(cur_value.group(1))
            if re.fullmatch(r"-?\d+", cur_value.group(1)):
                value = str(max(0, int(round(v * 10 ** rng.uniform(-1.5, 1.5)))))
            else:
                value = repr(v * 10 ** rng.uniform(-3, 3))
        # Replace the key in its table, or add it (and the table).
        cur, done = None, False
        for i, line in enumerate(lines):
            m = re.match(r"\[(\w+)\]", line)
            if m:
                cur = m.group(1)
            elif cur == table and re.match(rf"{key}\s*=", line):
                lines[i] = f"{key} = {value}"
                done = True
        if not done:
            lines.append(f"\n[{table}]\n{key} = {value}")
    return "\n".join(lines)


def main():
    sim, root = sys.argv[1], sys.argv[2]
    count = int(sys.argv[3]) if len(sys.argv) > 3 else 300
    base = open(os.path.join(root, "scenes", "tiny.toml")).read()
    keys = scene_keys(sim)
    rng = random.Random(20261123)
    tmp = tempfile.mkdtemp()
    url = "udpm://239.255.76.67:7696?ttl=0"
    refused = ran = fail = 0
    for n in range(count):
        text = mutate(base, rng, keys)
        # TOML allows a table once: a duplicate table is itself a refusal to test.
        path = os.path.join(tmp, f"s{n}.toml")
        with open(path, "w") as f:
            f.write(text)
        try:
            c = subprocess.run([sim, path, "--check"], capture_output=True, text=True, timeout=30)
        except subprocess.TimeoutExpired:
            print(f"FAIL scene {n}: --check hung\n{text}")
            fail += 1
            continue
        if c.returncode == 2 and ("invalid scene" in c.stderr or "sim_node:" in c.stderr):
            refused += 1
            continue
        if c.returncode != 0:
            print(f"FAIL scene {n}: --check exit {c.returncode}: {c.stderr.strip()[-300:]}\n{text}")
            fail += 1
            continue
        # Accepted: it must run.
        p = subprocess.Popen([sim, path, "--lcm-url", url, "--unauthenticated"], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                             text=True)
        try:
            _, err = p.communicate(timeout=RUN_SECONDS)
            rc = p.returncode
        except subprocess.TimeoutExpired:
            p.terminate()
            try:
                _, err = p.communicate(timeout=30)
            except subprocess.TimeoutExpired:
                p.kill()
                _, err = p.communicate()
            rc = None
        status = re.findall(r"\[(\w+)\s*\] t=(\S+)\s*/\S+\s+phi=(\S+)", err)
        if rc == 0:
            ran += 1
        elif rc is None and len(status) >= 2 and status[-1] != status[0]:
            ran += 1  # a longer run, still making progress when stopped
        else:
            print(f"FAIL scene {n}: accepted but exit {rc}, {len(status)} status lines: {err.strip()[-400:]}\n{text}")
            fail += 1
    print(f"{'ok  ' if fail == 0 else 'FAIL'} {count} mutated scenes: {refused} refused with a message, {ran} ran, "
          f"{fail} neither")
    return 1 if fail else 0


if __name__ == "__main__":
    sys.exit(main())
