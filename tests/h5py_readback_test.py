"""Recordings are readable with h5py alone: import a real fakenect dump with
record-session, once per codec (szip, and LZ4 through Debian's HDF5 filter
plugin), then read it back here and compare with the PGM files decoded by
numpy (little-endian, as libfreenect writes them)."""
import pathlib, subprocess, sys, tempfile

import h5py
import numpy as np

bin_dir, data = pathlib.Path(sys.argv[1]), pathlib.Path(sys.argv[2])
dump = data / "fakenect_openiss_depth"
for codec in ["szip", "lz4"]:
  with tempfile.TemporaryDirectory() as tmp:
    session = pathlib.Path(tmp) / "s"
    subprocess.run([bin_dir / "record-session", f"fakenect:{dump}", "--codec", codec, "--out", session], check=True,
                   stdout=subprocess.DEVNULL)
    names = [l for l in (dump / "INDEX.txt").read_text().split() if l.startswith("d-")]
    with h5py.File(session / "free.h5", "r") as f:
        assert f.attrs["schema"] == "speckle.recording", dict(f.attrs)
        assert f.attrs["schema_version"] == 1
        depth = f["depth/frames"]
        assert depth.attrs["units"] == "raw_11bit"
        assert depth.shape == (len(names), 480, 640), depth.shape
        for i, name in enumerate(names):
            raw = (dump / name).read_bytes()[17:]
            expected = np.frombuffer(raw, "<u2").reshape(480, 640)
            assert np.array_equal(depth[i], expected), name
        assert f["depth/valid"][:].all()
        assert len(f["accel/counts"]) > 0
print(f"2 passed, 0 failed")
