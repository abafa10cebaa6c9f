"""A host that loads an FMU with fmpy, steps it, frees it and exits; with allocator
traffic after the FMU's exit code (late_malloc.so) and a heap laid out so that the
block pythonfmu 0.7.0 frees at exit sits at the start of a free chunk.

    python host.py FMU LATE_MALLOC_SO      exit status 0, or killed by SIGABRT

The FMU is unpacked in /tmp whatever TMPDIR says: the layout depends on the length of the
folder's path (under a long TMPDIR, such as the test session's own, the corruption went
undetected).
"""
import ctypes
import shutil
import sys
import tempfile

from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave

fmu, late_malloc = sys.argv[1], sys.argv[2]
description = read_model_description(fmu)
folder = extract(fmu, unzipdir=tempfile.mkdtemp(dir="/tmp"))
slave = FMU2Slave(guid=description.guid, unzipDirectory=folder, instanceName="host",
                  modelIdentifier=description.coSimulation.modelIdentifier)
ctypes.CDLL(late_malloc)                  # after the FMU library: its destructor runs later
libc = ctypes.CDLL(None)
libc.malloc.restype = ctypes.c_void_p
for _ in range(1000):                     # leaked on purpose: the freed block keeps
    libc.malloc(128)                      # an allocated neighbour, so it is not merged
slave.instantiate()
slave.setupExperiment(startTime=0.0)
slave.enterInitializationMode()
slave.exitInitializationMode()
for k in range(10):
    slave.doStep(k * 0.1, 0.1)
slave.terminate()
slave.freeInstance()
shutil.rmtree(folder, ignore_errors=True)
