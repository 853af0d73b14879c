"""The HCI PFM reader the scripts share (lfformat::pfm writes the same layout)."""
import numpy as np


def read_pfm(path):
    """HCI PFM: a greyscale float map stored bottom row first."""
    with open(path, "rb") as f:
        assert f.readline().strip() == b"Pf", f"{path}: not a greyscale PFM"
        w, h = map(int, f.readline().split())
        scale = float(f.readline())
        data = np.frombuffer(f.read(), dtype="<f4" if scale < 0 else ">f4")
    return np.flipud(data.reshape(h, w))
