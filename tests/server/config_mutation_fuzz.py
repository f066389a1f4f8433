#!/usr/bin/env python3
"""Mutation fuzzing of covtrackd's shipped configs, run WITHOUT --check.

Each shipped config (and the Lenz track layout, through config/lenz.toml) is mutated
deterministically from --seed: numbers to huge, negative, zero, NaN, inf; strings to
empty, long, odd paths and format directives; arrays emptied or made huge; lines and
[[table]] blocks dropped or repeated; bits flipped. Every mutant runs as
`covtrackd --config MUTANT` inside a private network namespace (tests/netns_run.sh:
the daemon publishes multicast) for --seconds, then gets SIGTERM; then, if that went
well, `covtrackd --check --config MUTANT` runs. Outcomes:

  good  config-error    exit 2 with "the config has errors" (a clear error at load)
  good  ran             still running at the deadline, stopped on SIGTERM with 0
  good  runtime-exit    ended early by itself with code 1 and a message (shown, to judge)
  bad   sanitizer       AddressSanitizer / UndefinedBehaviorSanitizer / LeakSanitizer report
  bad   memory          out of memory (ulimit -v, or ASan's hard RSS limit)
  bad   crash           ended by a signal (an uncaught exception aborts) or with another code
  bad   slow-load       still reading the config at the deadline (ended by the SIGTERM, as documented)
  bad   stuck-stop      did not stop within --stop-grace seconds of SIGTERM, or code 4
  bad   check-failed    the run was good, but `covtrackd --check` of the mutant crashed, hung or
                        reported a sanitizer error (it must exit 0, or 2 with the config's errors)

Serial ports in the configs are first pointed into the scratch folder (no file there:
the drivers retry), so no mutant opens a device of this machine or another test's
emulator. Odd paths are only /dev/null, /dev/zero and paths in the scratch folder.

A sanitizer build (not in CI) finds more than a plain one:
  cmake -S . -B build-asan -DCMAKE_BUILD_TYPE=RelWithDebInfo "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O1 -g1" \
    "-DCMAKE_CXX_FLAGS=-fsanitize=address,undefined -fno-omit-frame-pointer" \
    "-DCMAKE_EXE_LINKER_FLAGS=-fsanitize=address,undefined" "-DCMAKE_SHARED_LINKER_FLAGS=-fsanitize=address,undefined"
  cmake --build build-asan -j2 --target covtrackd
  tests/server/config_mutation_fuzz.py --daemon build-asan/server/covtrackd --count 40
One mutant again: --only lenz_layout.toml:17 --keep-all (its files stay in --work).
Exit code: 0 when every mutant ended well, 1 otherwise.
"""
import argparse
import collections
import concurrent.futures
import os
import random
import re
import resource
import shutil
import signal
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
SOURCE = os.path.dirname(os.path.dirname(HERE))
GOOD = ("config-error", "ran", "runtime-exit")
SCRATCH = "@SCRATCH@"  # replaced by the mutant's own folder when it is written

NUMBERS = ["0", "-1", "-0.0", "1e308", "-1e308", "1e-320", "nan", "inf", "-inf", "+inf", "-nan",
           "9223372036854775807", "-9223372036854775808", "2147483648", "4294967296", "65536",
           "1000000000", "0.000001", "3.5", "-360", "1e3", "1e4"]
LONG = "x" * 5000


def odd_strings():
    return ["", " ", LONG, "/dev/null", "/dev/zero", f"{SCRATCH}", f"{SCRATCH}/fifo", f"{SCRATCH}/missing",
            f"{SCRATCH}/" + "a/" * 300, "../" * 40 + "x", "%s%s%s%n", "frame_%99999999d.png", "%d%d%d.png",
            "frame_%04d.png", "frame_%099999999999d.png", "x.png", "\\u0001", "\\u00e9\\u00e8", "0", "-1", "999999", "tag36h11",
            "li101f", "liusb", "is900", "patriot", "cm", "inch", "left", "Tracker0@localhost"]


# ---------------------------------------------------------------------------- text model

VALUE = re.compile(r'^(\s*)([A-Za-z0-9_]+)(\s*=\s*)(.*)$')


def split_value(rest):
    """The value text of `key = value  # comment`, and what follows it."""
    if rest.startswith('"'):
        end = rest.find('"', 1)
        while end > 0 and rest[end - 1] == "\\":
            end = rest.find('"', end + 1)
        end = len(rest) if end < 0 else end + 1
    elif rest.startswith("["):
        depth, end = 0, len(rest)
        for i, c in enumerate(rest):
            depth += c == "["
            depth -= c == "]"
            if depth == 0:
                end = i + 1
                break
    else:
        end = rest.find("#")
        end = len(rest) if end < 0 else end
        while end > 0 and rest[end - 1] == " ":
            end -= 1
    return rest[:end], rest[end:]


def kind_of(value):
    if value.startswith('"'):
        return "string"
    if value.startswith("["):
        return "array"
    if value in ("true", "false"):
        return "bool"
    return "number"


def value_lines(lines, kind=None):
    out = []
    for i, line in enumerate(lines):
        m = VALUE.match(line)
        if m and not line.lstrip().startswith("#") and (kind is None or kind_of(split_value(m.group(4))[0]) == kind):
            out.append(i)
    return out


def set_value(lines, i, new):
    m = VALUE.match(lines[i])
    _, tail = split_value(m.group(4))
    lines[i] = f"{m.group(1)}{m.group(2)}{m.group(3)}{new}{tail}"


def get_value(lines, i):
    return split_value(VALUE.match(lines[i]).group(4))[0]


def quote(s):
    return '"' + s.replace('"', '\\"') + '"'


# ---------------------------------------------------------------------------- mutators

def pick(lines, rng, kind=None):
    """A random line holding a value of `kind` (any when None), or None if there is none."""
    candidates = value_lines(lines, kind)
    return rng.choice(candidates) if candidates else None


def mutate_number(lines, rng):
    candidates = value_lines(lines, "number")
    arrays = [i for i in value_lines(lines, "array") if re.search(r"[-+0-9.]", get_value(lines, i))]
    if not candidates and not arrays:
        return False
    i = rng.choice(candidates + arrays)
    if i in arrays:  # one item of a number array
        items = [s.strip() for s in get_value(lines, i)[1:-1].split(",")]
        items[rng.randrange(len(items))] = rng.choice(NUMBERS)
        set_value(lines, i, "[" + ", ".join(items) + "]")
    else:
        set_value(lines, i, rng.choice(NUMBERS))
    return True


def mutate_string(lines, rng):
    i = pick(lines, rng, "string")
    if i is None:
        return False
    set_value(lines, i, quote(rng.choice(odd_strings())))
    return True


def mutate_type(lines, rng):
    i = pick(lines, rng)
    if i is None:
        return False
    set_value(lines, i, rng.choice(['"12"', "12", "true", "[]", "{}", "[[1, 2], [3]]",
                                                       '["a", 1]', "1979-05-27T07:32:00Z"]))
    return True


def mutate_bool(lines, rng):
    i = pick(lines, rng, "bool")
    if i is None:
        return False
    set_value(lines, i, "false" if get_value(lines, i) == "true" else "true")
    return True


def mutate_array(lines, rng):
    i = pick(lines, rng, "array")
    if i is None:
        return False
    items = [s.strip() for s in get_value(lines, i)[1:-1].split(",") if s.strip()]
    item = items[0] if items else "1"
    choice = rng.randrange(4)
    if choice == 0:
        set_value(lines, i, "[]")
    elif choice == 1:  # huge
        set_value(lines, i, "[" + ", ".join([item] * rng.choice([4, 100, 100000])) + "]")
    elif choice == 2:  # the items counted up, when they are names
        n = rng.choice([30, 1000, 20000])
        made = [quote(f"s{k}") if item.startswith('"') else str(k) for k in range(n)]
        set_value(lines, i, "[" + ", ".join(made) + "]")
    else:
        set_value(lines, i, "[" + ", ".join(items[:-1]) + "]")
    return True


def drop_line(lines, rng):
    candidates = [i for i, l in enumerate(lines) if l.strip() and not l.lstrip().startswith("#")]
    if not candidates:
        return False
    del lines[rng.choice(candidates)]
    return True


def duplicate_line(lines, rng):
    i = pick(lines, rng)
    if i is None:
        return False
    lines.insert(i + 1, lines[i])
    return True


def table_blocks(lines):
    """(start, end) of each [[array.of.tables]] entry: its header up to the next header."""
    heads = [i for i, l in enumerate(lines) if l.lstrip().startswith("[")]
    out = []
    for k, i in enumerate(heads):
        if lines[i].lstrip().startswith("[["):
            out.append((i, heads[k + 1] if k + 1 < len(heads) else len(lines)))
    return out


def pick_block(lines, rng):
    """One [[array.of.tables]] entry, or None when the file has none."""
    blocks = table_blocks(lines)
    return rng.choice(blocks) if blocks else None


def repeat_block(lines, rng):
    block = pick_block(lines, rng)
    if not block:
        return False
    start, end = block
    lines[end:end] = lines[start:end] * rng.choice([1, 2, 50, 3000])
    return True


def drop_block(lines, rng):
    block = pick_block(lines, rng)
    if not block:
        return False
    del lines[block[0]:block[1]]
    return True


MUTATORS = [mutate_number, mutate_number, mutate_number, mutate_string, mutate_string, mutate_type,
            mutate_bool, mutate_array, drop_line, duplicate_line, repeat_block, drop_block]


def flip_bits(text, rng):
    data = bytearray(text.encode())
    for _ in range(rng.randint(1, 4)):
        k = rng.randrange(len(data))
        data[k] ^= 1 << rng.randrange(8)
    return data.decode("latin-1")


def mutate(text, rng):
    """A mutant of `text`: one to three mutations, or a few flipped bits (one in eight)."""
    if rng.randrange(8) == 0:
        return flip_bits(text, rng), "flipped bits"
    lines = text.split("\n")
    done = []
    for _ in range(rng.choice([1, 1, 1, 2, 2, 3])):  # mostly one: more mutants get past validation
        for _attempt in range(10):
            m = rng.choice(MUTATORS)
            if m(lines, rng):
                done.append(m.__name__)
                break
    return "\n".join(lines), ", ".join(done)


# ---------------------------------------------------------------------------- running

SANITIZER = re.compile(r"ERROR: (AddressSanitizer|LeakSanitizer|UndefinedBehaviorSanitizer)|runtime error:")
MEMORY = re.compile(r"rss limit exhausted|allocation-size-too-big|out of memory|std::bad_alloc|"
                    r"requested allocation size|cannot allocate memory", re.I)


def classify(code, early, stderr, stopped_in_time):
    if SANITIZER.search(stderr):
        if MEMORY.search(stderr):
            return "memory"
        return "sanitizer"
    if MEMORY.search(stderr):
        return "memory"
    if not stopped_in_time:
        return "stuck-stop"
    if code == 2 and "the config has errors" in stderr:  # early, or just as the deadline came
        return "config-error"
    if early:
        if code == 1 and stderr.strip():
            return "runtime-exit"
        return "crash"
    if code == 0:
        return "ran"
    if code == -signal.SIGTERM:  # still reading the config: it ends by the signal, as documented
        return "slow-load"
    if code == 4:
        return "stuck-stop"
    return "crash"


def headline(stderr):
    """The line that says most about a bad outcome."""
    for pattern in (r"SUMMARY: .*", r".*runtime error:.*", r"terminate called.*", r"what\(\): .*",
                    r"ERROR: .*", r".*error.*"):
        m = re.search(pattern, stderr)
        if m:
            return m.group(0)[:240]
    lines = [l for l in stderr.splitlines() if l.strip()]
    return lines[-1][:240] if lines else "(no output)"


def uses_asan(daemon):
    out = subprocess.run(["ldd", daemon], capture_output=True, text=True).stdout
    return "libasan" in out


class Runner:
    def __init__(self, args):
        self.args = args
        self.asan = uses_asan(args.daemon)
        self.netns = os.path.join(HERE, "..", "netns_run.sh")

    def env(self, folder):
        env = dict(os.environ)
        env["COVTRACK_LOCK_DIR"] = folder
        env.pop("LCM_DEFAULT_URL", None)
        limit = self.args.memory_mb
        env["ASAN_OPTIONS"] = (f"hard_rss_limit_mb={limit}:max_allocation_size_mb={limit}:"
                               "allocator_may_return_null=0:detect_leaks=1:abort_on_error=0")
        env["UBSAN_OPTIONS"] = "print_stacktrace=1:halt_on_error=0"
        return env

    def limit_memory(self):
        os.setsid()
        if not self.asan:  # ASan reserves terabytes of address space: its RSS limit instead
            limit = self.args.memory_mb * 1024 * 1024
            resource.setrlimit(resource.RLIMIT_AS, (limit, limit))

    def run(self, folder, config):
        out_path = os.path.join(folder, "stderr.txt")
        with open(out_path, "w+") as out:
            start = time.monotonic()
            proc = subprocess.Popen([self.netns, self.args.daemon, "--config", config], cwd=folder,
                                    stdout=out, stderr=subprocess.STDOUT, env=self.env(folder),
                                    preexec_fn=self.limit_memory)
            early, stopped = True, True
            try:
                code = proc.wait(timeout=self.args.seconds)
            except subprocess.TimeoutExpired:
                early = False
                proc.send_signal(signal.SIGTERM)
                try:
                    code = proc.wait(timeout=self.args.stop_grace)
                except subprocess.TimeoutExpired:
                    stopped = False
                    os.killpg(proc.pid, signal.SIGKILL)
                    code = proc.wait()
            elapsed = time.monotonic() - start
            out.seek(0)
            stderr = out.read()
        if code < 0 and early:
            stderr += f"\n(ended by signal {signal.Signals(-code).name})"
        return classify(code, early, stderr, stopped), code, elapsed, stderr

    def check(self, folder, config):
        """`covtrackd --check` of the mutant: exit 0 or a clear config error, nothing else."""
        try:
            done = subprocess.run([self.args.daemon, "--check", "--config", config], cwd=folder, text=True,
                                  errors="replace", capture_output=True, env=self.env(folder),
                                  preexec_fn=self.limit_memory, timeout=self.args.stop_grace)
        except subprocess.TimeoutExpired:
            return "check-failed", None, f"--check still running after {self.args.stop_grace} s"
        out = done.stdout + done.stderr
        clean = done.returncode == 0 or (done.returncode == 2 and "the config has errors" in out)
        if clean and not SANITIZER.search(out):
            return None, done.returncode, out
        if done.returncode < 0:
            out += f"\n(ended by signal {signal.Signals(-done.returncode).name})"
        return "check-failed", done.returncode, out


# ---------------------------------------------------------------------------- the bases

def base_configs(source, names):
    """(target file name, text, host config name): every shipped daemon config, and the
    Lenz layout through lenz.toml."""
    config_dir = os.path.join(source, "config")
    out = []
    for name in sorted(os.listdir(config_dir)):
        if not name.endswith(".toml") or (names and name not in names):
            continue
        text = open(os.path.join(config_dir, name), encoding="latin-1").read()  # bytes as they are
        # Serial ports into the scratch folder: nothing of this machine is opened.
        text = re.sub(r'^(\s*port\s*=\s*)"[^"]*"', rf'\1"{SCRATCH}/port"', text, flags=re.M)
        host = "lenz.toml" if name == "lenz_layout.toml" else name
        out.append((name, text, host))
    return out


def prepare(folder, source, frames_root, host_name, files):
    """The scratch folder of one mutant: config/ with the shipped configs, one of them
    mutated, beside the shipped camera files, and build/ pointing at the rendered demo
    frames (the configs name them relative to their own folder)."""
    config = os.path.join(folder, "config")
    os.makedirs(config)
    os.symlink(os.path.join(source, "config", "cameras"), os.path.join(config, "cameras"))
    os.symlink(frames_root, os.path.join(folder, "build"))
    os.mkfifo(os.path.join(folder, "fifo"))
    for name, text in files.items():
        with open(os.path.join(config, name), "w", encoding="latin-1") as f:
            f.write(text.replace(SCRATCH, folder))
    return os.path.join(config, host_name)


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0],
                                formatter_class=argparse.RawDescriptionHelpFormatter, epilog=__doc__)
    p.add_argument("--daemon", required=True, help="the covtrackd to run (a sanitizer build finds more)")
    p.add_argument("--source", default=SOURCE, help="the checkout whose config/ is mutated")
    p.add_argument("--frames-root", help="folder holding fiducial_demo/ and fiducial_bundle_demo/ "
                   "(the build's; default: SOURCE/build)")
    p.add_argument("--count", type=int, default=20, help="mutants per config")
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--seconds", type=float, default=5.0, help="run time of each mutant before SIGTERM "
                   "(a sanitizer build on a loaded machine reads a 500 kB mutant in 1.5-3.5 s)")
    p.add_argument("--stop-grace", type=float, default=15.0, help="wait for the stop after SIGTERM")
    p.add_argument("--memory-mb", type=int, default=2048, help="address space limit (ASan: RSS limit)")
    p.add_argument("--jobs", type=int, default=2)
    p.add_argument("--configs", nargs="*", help="only these config/ file names")
    p.add_argument("--only", help="one mutant, NAME:INDEX (-1: the config as shipped)")
    p.add_argument("--work", help="scratch folder (default: a new temporary one)")
    p.add_argument("--keep-all", action="store_true", help="keep every mutant's folder, not only the bad ones")
    args = p.parse_args()
    args.daemon = os.path.abspath(args.daemon)
    source = os.path.abspath(args.source)
    frames_root = os.path.abspath(args.frames_root or os.path.join(source, "build"))
    work = os.path.abspath(args.work or tempfile.mkdtemp(prefix="covtrack_config_fuzz_"))
    os.makedirs(work, exist_ok=True)
    runner = Runner(args)

    bases = base_configs(source, args.configs)
    shipped = {name: text for name, text, _ in base_configs(source, None)}
    jobs = []
    for name, text, host in bases:
        for index in range(-1, args.count):  # -1: the config as shipped, which must run
            if args.only and args.only != f"{name}:{index}":
                continue
            jobs.append((name, index, text, host))
    if args.only and not jobs:
        p.error(f"--only {args.only}: no such mutant (NAME:INDEX, INDEX below --count)")

    def one(job):
        name, index, text, host = job
        rng = random.Random(f"{args.seed}:{name}:{index}")
        mutant, how = mutate(text, rng) if index >= 0 else (text, "as shipped")
        folder = os.path.join(work, f"{name[:-5]}_{index:03d}" if index >= 0 else f"{name[:-5]}_shipped")
        shutil.rmtree(folder, ignore_errors=True)
        files = dict(shipped, **{name: mutant})
        config = prepare(folder, source, frames_root, host, files)
        outcome, code, elapsed, stderr = runner.run(folder, config)
        if outcome in GOOD:  # the run was fine: then --check must be too
            failed, check_code, check_out = runner.check(folder, config)
            if failed:
                outcome, code, stderr = failed, check_code, check_out
        if outcome in GOOD and not args.keep_all:
            shutil.rmtree(folder, ignore_errors=True)
        return name, index, how, outcome, code, elapsed, stderr, folder

    print(f"{len(jobs)} mutants of {len(bases)} config(s), seed {args.seed}, {args.seconds} s each, "
          f"{'ASan/UBSan build' if runner.asan else 'plain build'}; scratch: {work}", flush=True)
    counts = collections.defaultdict(collections.Counter)
    bad, shipped_bad = [], []
    with concurrent.futures.ThreadPoolExecutor(args.jobs) as pool:
        for name, index, how, outcome, code, elapsed, stderr, folder in pool.map(one, jobs):
            if index < 0:
                if outcome != "ran":
                    shipped_bad.append(name)
                    print(f"SHIPPED {name} does not run: {outcome} (code {code}): {headline(stderr)}", flush=True)
                continue
            counts[name][outcome] += 1
            if outcome not in GOOD:
                bad.append((name, index, outcome, how, headline(stderr), folder))
                print(f"BAD {name}:{index} {outcome} (code {code}, {elapsed:.1f} s; {how}): {headline(stderr)}",
                      flush=True)
            elif outcome == "runtime-exit" or args.only:
                print(f"{name}:{index} {outcome} (code {code}; {how}): {headline(stderr)}", flush=True)

    outcomes = list(GOOD) + ["sanitizer", "memory", "crash", "slow-load", "stuck-stop", "check-failed"]
    print("\n| config | " + " | ".join(outcomes) + " |")
    print("|---|" + "---|" * len(outcomes))
    total = collections.Counter()
    for name, c in sorted(counts.items()):
        total.update(c)
        print(f"| {name} | " + " | ".join(str(c[o]) for o in outcomes) + " |")
    print("| all | " + " | ".join(str(total[o]) for o in outcomes) + " |")
    mutants = sum(sum(c.values()) for c in counts.values())
    print(f"\n{mutants} mutants, {len(bad)} bad" + (f"; their folders are in {work}" if bad else ""))
    if shipped_bad:
        print(f"as shipped, these do not run (the harness is wrong, or the config): {', '.join(shipped_bad)}")
    return 1 if bad or shipped_bad else 0


if __name__ == "__main__":
    sys.exit(main())
