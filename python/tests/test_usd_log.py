"""uwbtdoa.import_usd_log: a Crazyflie uSD-card event log written here byte by byte (the cfusdlog layout,
docs/io.md section 6), imported with UTIL's units; errors as ValueError with the byte and event."""
import struct
import zlib

import numpy as np
import pytest

import uwbtdoa as u


def _cfusdlog(types, events, version=2):
    """types: [(id, name, ["field(T)", ...])]; events: [(id, t_us, values)] in file order. Returns the file bytes."""
    fmts = {}
    out = bytearray(struct.pack("<BHH", 0xBC, version, len(types)))
    for tid, name, fields in types:
        out += struct.pack("<H", tid) + name.encode() + b"\0" + struct.pack("<H", len(fields))
        for f in fields:
            out += f.encode() + b"\0"
        fmts[tid] = "<" + "".join(f[-2] for f in fields)
    fmts.setdefault(99, "<")  # an id the header does not declare (empty payload)
    for tid, t_us, values in events:
        stamp = struct.pack("<I", t_us // 1000) if version == 1 else struct.pack("<Q", t_us)
        out += struct.pack("<H", tid) + stamp + struct.pack(fmts[tid], *values)
    return bytes(out + struct.pack("<I", zlib.crc32(bytes(out)) & 0xFFFFFFFF))


TYPES = [(10, "estTDOA", ["idA(B)", "idB(B)", "distanceDiff(f)"]),
         (11, "estAcceleration", ["acc.x(f)", "acc.y(f)", "acc.z(f)"]),
         (12, "estGyroscope", ["gyro.x(f)", "gyro.y(f)", "gyro.z(f)"]),
         (13, "estTOF", ["range.zrange(H)"]),
         (14, "estPose", ["locSrv.x(f)", "locSrv.y(f)", "locSrv.z(f)", "locSrv.qx(f)", "locSrv.qy(f)",
                          "locSrv.qz(f)", "locSrv.qw(f)"])]
EVENTS = [(11, 2000, (0.0, 0.0, 1.0)),
          (12, 2010, (10.0, 0.0, -5.0)),
          (10, 2500, (7, 0, -1.25)),
          (14, 3000, (1.5, 0.25, 0.75, 0.0, 0.0, 0.0, 1.0)),
          (13, 4000, (1234,)),
          (11, 3000, (0.5, -0.25, 1.0)),
          (10, 4500, (0, 1, 2.5))]


def test_import_converts_units_and_reports_the_sources(tmp_path):
    # GIVEN a log as the UTIL firmware wrote it
    path = tmp_path / "flight.log"
    path.write_bytes(_cfusdlog(TYPES, EVENTS))
    # WHEN it is imported
    f, report = u.import_usd_log(str(path), with_report=True)
    # THEN the streams hold the values in SI units on a clock starting at the first event
    np.testing.assert_array_equal(f.tdoa["t"], [0.0005, 0.0025])
    np.testing.assert_array_equal(f.tdoa["id_a"], [7, 0])
    np.testing.assert_array_equal(f.tdoa["tdoa"], [-1.25, 2.5])
    np.testing.assert_array_equal(f.acc["t"], [0.0, 0.001])
    np.testing.assert_array_equal(f.acc["value"][1], np.array([0.5, -0.25, 1.0]) * 9.81)
    np.testing.assert_allclose(f.gyro["value"][0], np.radians([10.0, 0.0, -5.0]), rtol=1e-15)
    np.testing.assert_array_equal(f.tof["value"], [1.234])
    np.testing.assert_array_equal(f.pose["p"][0], [1.5, 0.25, 0.75])
    assert report["t0_us"] == 2000.0
    assert [s["event"] for s in report["sources"]] == ["estTDOA", "estAcceleration", "estGyroscope", "estTOF", "estPose"]
    assert report["notes"] == []
    # AND the flight CSV written from it reads back exactly, and write_usd_log/import_usd_log round-trip
    u.write_flight_csv(f, str(tmp_path / "f.csv"))
    g = u.read_flight_csv(str(tmp_path / "f.csv"))
    np.testing.assert_array_equal(g.acc["value"], f.acc["value"])
    u.write_usd_log(f, str(tmp_path / "again.log"))
    h = u.import_usd_log(str(tmp_path / "again.log"))
    np.testing.assert_array_equal(h.tdoa["t"], f.tdoa["t"])
    np.testing.assert_allclose(h.acc["value"], f.acc["value"], rtol=1e-7)


def test_bad_logs_raise_value_error_with_byte_and_event(tmp_path):
    good = _cfusdlog(TYPES, EVENTS)
    bad_magic = tmp_path / "magic.log"
    bad_magic.write_bytes(b"\x00" + good[1:])
    with pytest.raises(ValueError, match=r"magic\.log: byte 0 \(magic\): bad magic byte 0x00"):
        u.import_usd_log(str(bad_magic))
    damaged = bytearray(good)
    damaged[-10] ^= 0xFF
    (tmp_path / "crc.log").write_bytes(bytes(damaged))
    with pytest.raises(ValueError, match=r"\(crc\): CRC mismatch"):
        u.import_usd_log(str(tmp_path / "crc.log"))
    unknown = _cfusdlog(TYPES, EVENTS[:2] + [(99, 5000, ())])
    (tmp_path / "id.log").write_bytes(unknown)
    with pytest.raises(ValueError, match=r"event 2 \(id\): event id 99 is not declared"):
        u.import_usd_log(str(tmp_path / "id.log"))
    # A cut log: refused by default, read up to its last complete event with salvage=True.
    (tmp_path / "cut.log").write_bytes(good[:-9])
    with pytest.raises(ValueError, match="salvage"):
        u.import_usd_log(str(tmp_path / "cut.log"))
    f = u.import_usd_log(str(tmp_path / "cut.log"), salvage=True)
    assert len(f.tdoa["t"]) == 1
    with pytest.raises(OSError):
        u.import_usd_log(str(tmp_path / "missing.log"))
