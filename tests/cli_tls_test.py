#!/usr/bin/python3
"""`isowall serve` and `isowall view` over TLS on the command line, as a user runs them:
a certificate made with `openssl`, `serve --tls-cert --tls-key`, `view --tls-ca` gets the same
image as a plain view of a plain server; a plain view against the TLS port, a TLS view against the
plain port, a certificate the view does not trust, bad certificate files and a non-loopback
address without TLS each end with one line and a non-zero exit, and write no image.

Usage: cli_tls_test.py ISOWALL [DIR]   (DIR, emptied first: where its files go; else a temp folder)
"""
import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
COMPARE = os.path.join(os.path.dirname(HERE), "web", "test", "compare_images.py")
failures = []


def check(ok, what):
    print(("ok   " if ok else "FAIL ") + what, flush=True)
    if not ok:
        failures.append(what)


def make_cert(d, name, san="DNS:localhost,IP:127.0.0.1"):
    cert, key = os.path.join(d, name + ".crt"), os.path.join(d, name + ".key")
    subprocess.run(["openssl", "req", "-x509", "-newkey", "ec", "-pkeyopt",
                    "ec_paramgen_curve:prime256v1", "-nodes", "-days", "1", "-subj",
                    "/CN=" + name, "-addext", "subjectAltName=" + san, "-keyout", key, "-out",
                    cert], check=True, capture_output=True)
    return cert, key


class Serve:
    """`isowall serve --port 0 ARGS` until stopped; .port is the TCP port it printed."""

    def __init__(self, isowall, args, log):
        self.log = log
        self.proc = subprocess.Popen([isowall, "serve", "--port", "0", *args],
                                     stdout=open(log, "w"), stderr=subprocess.STDOUT)
        self.port = None
        for _ in range(300):
            text = open(log).read()
            m = re.search(r"listening on \S+:(\d+)", text)
            if m and "(TLS)" in text and "TLS certificate" not in text:
                m = None  # the certificate's line follows the listening one
            if m:
                self.port = int(m.group(1))
                return
            if self.proc.poll() is not None:
                break
            time.sleep(0.1)
        raise SystemExit("cli_tls_test: serve printed no port:\n" + open(log).read())

    def stop(self):
        self.proc.terminate()
        self.proc.wait(timeout=30)


def run(isowall, args):
    return subprocess.run([isowall, *args], capture_output=True, text=True, timeout=120)


def expect_one_line(r, words, what, image=None):
    lines = r.stderr.strip().splitlines()
    ok = r.returncode != 0 and len(lines) == 1 and all(w in r.stderr for w in words)
    check(ok, f"{what}: one line naming {words} (exit {r.returncode}): {r.stderr.strip()!r}")
    if image:
        check(not os.path.exists(image), f"{what}: no image written")


def main():
    isowall = sys.argv[1]
    if len(sys.argv) > 2:
        d = sys.argv[2]
        shutil.rmtree(d, ignore_errors=True)
        os.makedirs(d)
    else:
        d = tempfile.mkdtemp(prefix="cli_tls_")
    cert, key = make_cert(d, "server")
    other_cert, other_key = make_cert(d, "other")
    tls = Serve(isowall, ["--tls-cert", cert, "--tls-key", key], os.path.join(d, "tls.log"))
    plain = Serve(isowall, [], os.path.join(d, "plain.log"))
    try:
        check("(TLS)" in open(tls.log).read(), "serve says it listens with TLS")
        summary = re.search(r"TLS certificate: (.*)", open(tls.log).read())
        check(summary is not None and "/CN=server" in summary.group(1) and "IP:127.0.0.1" in
              summary.group(1) and "valid until" in summary.group(1),
              "serve names its certificate: " + (summary.group(1) if summary else "no line"))
        view = ["view", "--size", "320x240", "--orbit", "30", "10"]
        a = os.path.join(d, "tls.png")
        r = run(isowall, [*view, "--connect", f"127.0.0.1:{tls.port}", "--tls-ca", cert,
                          "--out", a])
        check(r.returncode == 0 and os.path.exists(a), f"view --tls-ca: image ({r.stderr.strip()})")
        b = os.path.join(d, "plain.png")
        r = run(isowall, [*view, "--connect", f"127.0.0.1:{plain.port}", "--out", b])
        check(r.returncode == 0, f"plain view: image ({r.stderr.strip()})")
        c = subprocess.run(["/usr/bin/python3", COMPARE, a, b, "--min-iou", "0.999",
                            "--min-within2", "0.999"], capture_output=True, text=True)
        check(c.returncode == 0, "the TLS view's image equals the plain one: " + c.stdout.strip())

        bad = os.path.join(d, "bad.png")
        expect_one_line(run(isowall, [*view, "--connect", f"127.0.0.1:{tls.port}", "--out", bad]),
                        ["TLS", "--tls"], "plain view on the TLS port", bad)
        expect_one_line(run(isowall, [*view, "--connect", f"127.0.0.1:{plain.port}", "--tls-ca",
                                      cert, "--out", bad]),
                        ["TLS", "plain port"], "TLS view on the plain port", bad)
        expect_one_line(run(isowall, [*view, "--connect", f"127.0.0.1:{tls.port}", "--tls-ca",
                                      other_cert, "--out", bad]),
                        ["not trusted", "--tls-ca"], "a certificate the view does not trust", bad)
        expect_one_line(run(isowall, [*view, "--connect", f"127.0.0.1:{tls.port}", "--tls-ca",
                                      os.path.join(d, "none.pem"), "--out", bad]),
                        ["none.pem", "--tls-ca"], "an unreadable --tls-ca", bad)
    finally:
        tls.stop()
        plain.stop()
    check("spoke plain text" in open(tls.log).read(), "the TLS server logs the plain client")

    # A signal ends serve as it ends every command: the server closes its connections, says so,
    # and the signal ends the process (128 + signal in a shell).
    for sig in (signal.SIGINT, signal.SIGTERM, signal.SIGHUP):
        s = Serve(isowall, [], os.path.join(d, f"signal{int(sig)}.log"))
        s.proc.send_signal(sig)
        rc = s.proc.wait(timeout=60)
        check(rc == -int(sig), f"serve ends by {sig.name} (got exit {rc})")
        check("stopped after" in open(s.log).read(), f"serve says it stopped on {sig.name}")

    def serve_error(args, words, what):
        expect_one_line(run(isowall, ["serve", "--port", "0", *args]), words, what)

    serve_error(["--tls-cert", cert, "--tls-key", other_key], ["other.key", "does not match"],
                "a key of another certificate")
    serve_error(["--tls-cert", key, "--tls-key", key], ["--tls-cert", "not a PEM certificate"],
                "a key given as the certificate")
    serve_error(["--tls-cert", cert], ["--tls-cert", "--tls-key"], "a certificate without a key")
    serve_error(["--listen", "0.0.0.0", "--token", "s"], ["--listen", "TLS"],
                "a non-loopback address without TLS")
    serve_error(["--listen", "0.0.0.0", "--tls-cert", cert, "--tls-key", key],
                ["--listen", "--token"], "a non-loopback address without a token")
    if failures:
        sys.exit(f"cli_tls_test: {len(failures)} check(s) failed")
    print("cli_tls_test: all checks pass")


if __name__ == "__main__":
    main()
