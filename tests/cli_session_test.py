#!/usr/bin/python3
"""Shared sessions on the command line, as users run them: `view --present s` and a
`view --follow s --frames 2` that joins after the first view (it catches up with it, then gets the
second); the follower's last image equals the presenter's, and it names the presenter. A follower
of no session, a client that both presents and follows, and a follower that asks for a view each
end with one line and a non-zero exit.

Usage: cli_session_test.py ISOWALL [DIR]   (DIR, emptied first: where its files go)
"""
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from cli_tls_test import COMPARE, Serve, check, expect_one_line, failures, run  # noqa: E402


def wait_for(path, pattern, proc, limit_s=120):
    end = time.time() + limit_s
    while time.time() < end:
        if re.search(pattern, open(path).read()):
            return True
        if proc.poll() is not None:
            return False
        time.sleep(0.1)
    return False


def main():
    isowall = sys.argv[1]
    d = sys.argv[2] if len(sys.argv) > 2 else tempfile.mkdtemp(prefix="cli_session_")
    shutil.rmtree(d, ignore_errors=True)
    os.makedirs(d)
    serve = Serve(isowall, [], os.path.join(d, "serve.log"))
    at = f"127.0.0.1:{serve.port}"
    try:
        script = os.path.join(d, "present.txt")
        # The second view waits for the follower's line, so the follower joins between the two.
        open(script, "w").write("wait done\nwait time 4\norbit 30 10\nwait done\nwait time 1\n")
        shown = os.path.join(d, "presenter.png")
        plog = os.path.join(d, "presenter.log")
        presenter = subprocess.Popen(
            [isowall, "view", "--connect", at, "--size", "320x240", "--present", "s", "--script",
             script, "--out", shown], stdout=open(plog, "w"), stderr=subprocess.STDOUT)
        check(wait_for(plog, r"view: frame 1 done", presenter), "the presenter's first view")
        followed = os.path.join(d, "follower.png")
        flog = os.path.join(d, "follower.log")
        follower = subprocess.Popen(
            [isowall, "view", "--connect", at, "--follow", "s", "--frames", "2", "--out",
             followed], stdout=open(flog, "w"), stderr=subprocess.STDOUT)
        check(presenter.wait(timeout=120) == 0, "the presenter ends: " + open(plog).read()[-200:])
        check(follower.wait(timeout=120) == 0, "the follower ends after 2 frames: " +
              open(flog).read()[-300:])
        text = open(flog).read()
        check(len(re.findall(r"view: frame \d+ done", text)) == 2, "the follower drew 2 frames")
        check(re.search(r"session s, presenter 127\.0\.0\.1:\d+, 2 member", text) is not None,
              "the follower names the session's presenter")
        c = subprocess.run(["/usr/bin/python3", COMPARE, followed, shown, "--min-iou", "0.999",
                            "--min-within2", "0.999"], capture_output=True, text=True)
        check(c.returncode == 0, "the follower's last image equals the presenter's: " +
              c.stdout.strip())
        log = open(serve.log).read()
        check("presents session s" in log and "follows session s" in log,
              "serve says who presents and who follows")

        bad = os.path.join(d, "bad.png")
        expect_one_line(run(isowall, ["view", "--connect", at, "--follow", "nobody", "--out",
                                      bad]), ["no session", "nobody"], "--follow of no session",
                        bad)
        expect_one_line(run(isowall, ["view", "--connect", at, "--present", "a", "--follow", "a",
                                      "--out", bad]), ["--follow"], "--present and --follow", bad)
        expect_one_line(run(isowall, ["view", "--connect", at, "--follow", "s", "--orbit", "1",
                                      "0", "--out", bad]), ["asks for no views"],
                        "a follower with --orbit", bad)
    finally:
        serve.stop()
    if failures:
        print(f"cli_session_test: {len(failures)} check(s) failed")
        return 1
    print("cli_session_test: all checks pass")
    return 0


if __name__ == "__main__":
    sys.exit(main())
