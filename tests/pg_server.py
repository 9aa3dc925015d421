"""A throw-away PostgreSQL server for the store's tests, started from the machine's own binaries.

The binaries are looked for on PATH, in ``pg_config --bindir`` and in Debian's
``/usr/lib/postgresql/<version>/bin`` (where .ci/run's ``apt-get install postgresql`` puts them).
initdb refuses to run as root: as root the server runs as the ``postgres`` user when there is one,
else ``nobody``, else a system user ``gyrocal-pg`` created with useradd. Its data directory and Unix
socket live in a fresh temporary directory (readable by that user), removed at :meth:`stop`.
"""

from __future__ import annotations

import glob
import os
import pwd
import shutil
import socket
import subprocess
import tempfile
from pathlib import Path

SUPERUSER = "gyrocal"


class MissingPostgres(RuntimeError):
    """No PostgreSQL server binaries on this machine."""


def _bindirs() -> list[Path]:
    dirs = []
    pg_config = shutil.which("pg_config")
    if pg_config:
        out = subprocess.run([pg_config, "--bindir"], capture_output=True, text=True, check=False)
        if out.returncode == 0 and out.stdout.strip():
            dirs.append(Path(out.stdout.strip()))
    versions = sorted(glob.glob("/usr/lib/postgresql/*/bin"), key=lambda p: int(Path(p).parent.name)
                      if Path(p).parent.name.isdigit() else 0, reverse=True)
    return dirs + [Path(p) for p in versions] + [Path("/usr/local/pgsql/bin")]


def find_binary(name: str) -> str:
    """The path of PostgreSQL program `name` (initdb, pg_ctl); MissingPostgres when there is none."""
    found = shutil.which(name)
    if found:
        return found
    for bindir in _bindirs():
        if (bindir / name).is_file() and os.access(bindir / name, os.X_OK):
            return str(bindir / name)
    raise MissingPostgres(f"PostgreSQL's {name} not found on PATH, in pg_config --bindir or /usr/lib/postgresql/*/bin; "
                          "install the server (apt-get install postgresql), as .ci/run does")


def free_port() -> int:
    """A TCP port nothing listens on right now."""
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as sock:
        sock.bind(("127.0.0.1", 0))
        return sock.getsockname()[1]


def _server_user() -> pwd.struct_passwd | None:
    """None when not root (the server runs as the current user), else the unprivileged user to run it as."""
    if os.geteuid() != 0:
        return None
    for name in ("postgres", "nobody"):
        try:
            return pwd.getpwnam(name)
        except KeyError:
            continue
    subprocess.run(["useradd", "--system", "--no-create-home", "--shell", "/usr/sbin/nologin", "gyrocal-pg"],
                   check=True, capture_output=True)
    return pwd.getpwnam("gyrocal-pg")


class PostgresServer:
    """One server on 127.0.0.1:`port`, superuser ``gyrocal`` with trust authentication."""

    def __init__(self):
        self.initdb = find_binary("initdb")
        self.pg_ctl = find_binary("pg_ctl")
        self.user = _server_user()
        self.root = Path(tempfile.mkdtemp(prefix="gyrocal-pg-"))
        self.data = self.root / "data"
        self.port = free_port()
        self.started = False

    def _run(self, *args: str, timeout: float = 60) -> None:
        extra = {}
        env = dict(os.environ, LC_ALL="C", TZ="UTC")
        if self.user is not None:
            extra = {"user": self.user.pw_uid, "group": self.user.pw_gid, "extra_groups": []}
            env["HOME"] = str(self.root)
        out = subprocess.run(list(args), cwd=self.root, env=env, capture_output=True, text=True, timeout=timeout,
                             check=False, **extra)
        if out.returncode != 0:
            log = self.root / "server.log"
            tail = log.read_text()[-2000:] if log.exists() else ""
            raise RuntimeError(f"{' '.join(args)} failed ({out.returncode}): {out.stderr.strip()} {tail}")

    def start(self) -> None:
        if self.user is not None:
            os.chown(self.root, self.user.pw_uid, self.user.pw_gid)
        self._run(self.initdb, "-D", str(self.data), "-U", SUPERUSER, "--auth=trust", "-E", "UTF8", "--no-sync")
        # a time zone other than UTC, so the tests see that timestamps come back in UTC anyway
        options = (f"-p {self.port} -k {self.root} -c listen_addresses=127.0.0.1 -c fsync=off "
                   "-c synchronous_commit=off -c full_page_writes=off -c timezone=Europe/Berlin")
        self._run(self.pg_ctl, "-D", str(self.data), "-o", options, "-l", str(self.root / "server.log"), "-w",
                  "-t", "60", "start", timeout=90)
        self.started = True

    def url(self, database: str) -> str:
        return f"postgresql://{SUPERUSER}@127.0.0.1:{self.port}/{database}"

    def create_database(self, name: str) -> str:
        """Create database `name`; its store URL."""
        import psycopg

        with psycopg.connect(host="127.0.0.1", port=self.port, user=SUPERUSER, dbname="postgres",
                             autocommit=True) as connection:
            connection.execute(f'CREATE DATABASE "{name}"')
        return self.url(name)

    def stop(self) -> None:
        try:
            if self.started:
                self._run(self.pg_ctl, "-D", str(self.data), "-m", "fast", "-w", "stop", timeout=60)
        finally:
            shutil.rmtree(self.root, ignore_errors=True)
