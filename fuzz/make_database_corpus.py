#!/usr/bin/python3
"""Regenerates fuzz/corpus/database/: a valid rope database and the corrupted
copies that once crashed or misled contactrom (tests/cli/test_bad_input.cpp runs
every command on them). Run it after a change of the database format:

    /usr/bin/python3 fuzz/make_database_corpus.py build/tools/contactrom
"""
import os
import shutil
import subprocess
import sys

import h5py
import numpy as np

from hdf5_checksum import lookup3

exe = sys.argv[1] if len(sys.argv) > 1 else "build/tools/contactrom"
out = os.path.join(os.path.dirname(os.path.abspath(__file__)), "corpus", "database")
os.makedirs(out, exist_ok=True)
rope = os.path.join(out, "rope.h5")
if os.path.exists(rope):
    os.remove(rope)
subprocess.run([exe, "offline", "--problem", "rope", "--threads", "1", "--out", rope], check=True,
               stdout=subprocess.DEVNULL)


def rechecksum(f, name):
    """Stores the checksum of a dataset whose data a corruption changed, so that the
    reader's deeper checks (not the checksum) see the change."""
    data = f[name][()]
    f[name].attrs.create("checksum_lookup3", lookup3(data.tobytes()), dtype="<u4")


def corrupt(name, change):
    path = os.path.join(out, name)
    shutil.copyfile(rope, path)
    with h5py.File(path, "a") as f:
        change(f)


def string_array(f):  # an array where a single string belongs
    f.attrs.create("created_by", np.array([b"a", b"b", b"c"], dtype="S1"))


def vlen_string(f):  # h5py writes a Python str as a variable-length string
    f.attrs["problem"] = "rope"


def huge_vector(f):  # a chunked dataset declaring 2^32 elements in a small file
    del f["time_s"]
    f.create_dataset("time_s", shape=(2**32,), dtype="f8", chunks=(1024,))


def huge_columns(f):
    del f["primal"]
    f.create_dataset("primal", shape=(9, 2**62), dtype="f8", chunks=(1, 1024))


def negative_pressure(f):
    f["dual"][1, 3] = -1.0
    rechecksum(f, "dual")


def training_size_0(f):
    f.attrs["training_size"] = np.int32(0)


corrupt("string_attribute_array.h5", string_array)
corrupt("variable_length_string.h5", vlen_string)
corrupt("declared_2e32_elements.h5", huge_vector)
corrupt("declared_2e62_columns.h5", huge_columns)
corrupt("negative_pressure.h5", negative_pressure)
corrupt("training_size_0.h5", training_size_0)
# The reduced model of the valid database.
rom = os.path.join(os.path.dirname(out), "reduced_model", "rope_greedy.h5")
if os.path.exists(rom):
    os.remove(rom)
subprocess.run([exe, "reduce", "--db", rope, "--method", "greedy", "--out", rom], check=True, stdout=subprocess.DEVNULL)
print("corpus written to", out, "and", rom)
