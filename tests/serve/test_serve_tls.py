"""`physcam serve --cert --key`: HTTPS, the secure context phones on the set's network need to install the
page's offline copy (service workers run only on https:// and localhost). A real server process, a
certificate made here by openssl for 127.0.0.1, and a client that verifies it against that certificate."""

from __future__ import annotations

import json
import re
import shutil
import ssl
import subprocess
import sys
import time
import urllib.request

import pytest

from physcam.cli import main

OPENSSL = shutil.which("openssl")


@pytest.fixture(scope="module")
def cert(tmp_path_factory):
    if OPENSSL is None:
        pytest.skip("openssl is not installed: no certificate to serve")
    d = tmp_path_factory.mktemp("tls")
    crt, key = d / "cert.pem", d / "key.pem"
    subprocess.run([OPENSSL, "req", "-x509", "-newkey", "rsa:2048", "-nodes", "-keyout", str(key), "-out", str(crt),
                    "-days", "2", "-subj", "/CN=127.0.0.1", "-addext", "subjectAltName=IP:127.0.0.1"],
                   check=True, capture_output=True)
    return crt, key


@pytest.mark.slow
def test_serves_https_with_a_certificate(cert):
    crt, key = cert
    proc = subprocess.Popen([sys.executable, "-m", "physcam", "serve", "--port", "0", "--cert", str(crt), "--key",
                             str(key)], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        url = None
        t0 = time.monotonic()
        while url is None and time.monotonic() - t0 < 90:
            line = proc.stdout.readline()
            m = re.search(r"listening on (https://127\.0\.0\.1:\d+/)", line)
            url = m.group(1) if m else None
        assert url, "no https URL printed"
        ctx = ssl.create_default_context(cafile=str(crt))  # verified: the certificate names 127.0.0.1
        for _ in range(100):
            try:
                with urllib.request.urlopen(url + "api/health", context=ctx, timeout=10) as r:
                    assert r.status == 200 and json.loads(r.read())["ok"] is True
                break
            except OSError:
                time.sleep(0.1)
        else:
            raise AssertionError("the HTTPS server did not answer")
        with urllib.request.urlopen(url + "sw.js", context=ctx, timeout=10) as r:
            assert r.status == 200
    finally:
        proc.terminate()
        proc.wait(timeout=15)


def test_a_certificate_needs_its_key(cert, capsys, tmp_path):
    crt, key = cert
    assert main(["serve", "--port", "0", "--cert", str(crt), "--check"]) == 2
    assert "both --cert and --key" in capsys.readouterr().err
    bad = tmp_path / "bad.pem"
    bad.write_text("not a key\n")
    assert main(["serve", "--port", "0", "--cert", str(crt), "--key", str(bad), "--check"]) == 2
    err = capsys.readouterr().err
    assert "do not load" in err and "Traceback" not in err
