"""Exit 1 unless two fields.h5 files hold the same datasets with the same bits.

usage: same_fields.py A.h5 B.h5  (tests/mpi/same_history.sh: the field frames
written from blocks of each rank's owned rows must not depend on the
decomposition)."""
import sys

import h5py
import numpy as np


def datasets(f):
    names = []
    f.visit(lambda n: names.append(n) if isinstance(f[n], h5py.Dataset) else None)
    return names


def main(a_path, b_path):
    with h5py.File(a_path, "r") as a, h5py.File(b_path, "r") as b:
        names = datasets(a)
        if names != datasets(b):
            print(f"{b_path}: datasets {datasets(b)[:5]}... differ from {a_path}'s {names[:5]}...")
            return 1
        for n in names:
            x, y = a[n][()], b[n][()]
            if x.dtype != y.dtype or x.shape != y.shape or x.tobytes() != y.tobytes():
                print(f"{b_path}: {n} differs from {a_path}")
                return 1
        print(f"{len(names)} datasets bitwise equal")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1], sys.argv[2]))
