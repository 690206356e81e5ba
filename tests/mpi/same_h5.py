"""Exit 1 unless two HDF5 files hold the same groups, datasets and attributes,
with the same bits: the field frames (tests/mpi/same_history.sh) and the
checkpoints (tests/mpi/same_checkpoint.sh) written from blocks of each rank's
own rows must not depend on the decomposition.

usage: same_h5.py A.h5 B.h5"""
import sys

import h5py


def objects(f):
    names = ["/"]
    f.visit(names.append)
    return names


def main(a_path, b_path):
    with h5py.File(a_path, "r") as a, h5py.File(b_path, "r") as b:
        names = objects(a)
        if names != objects(b):
            print(f"{b_path}: objects {objects(b)} differ from {a_path}'s {names}")
            return 1
        datasets = 0
        for n in names:
            x, y = a[n], b[n]
            if sorted(x.attrs) != sorted(y.attrs):
                print(f"{b_path}: {n} has attributes {sorted(y.attrs)}, {a_path} {sorted(x.attrs)}")
                return 1
            for k in x.attrs:
                if repr(x.attrs[k]) != repr(y.attrs[k]):
                    print(f"{b_path}: attribute {k} of {n} is {y.attrs[k]!r}, in {a_path} {x.attrs[k]!r}")
                    return 1
            if isinstance(x, h5py.Dataset):
                datasets += 1
                p, q = x[()], y[()]
                if p.dtype != q.dtype or p.shape != q.shape or p.tobytes() != q.tobytes():
                    print(f"{b_path}: dataset {n} differs from {a_path}'s")
                    return 1
        print(f"{datasets} datasets and every attribute bitwise equal")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1], sys.argv[2]))
