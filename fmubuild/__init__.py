"""Building FMUs, on the host: no FMU carries this package.

- ``project``: this project's FMUs, their scripts and where they are built to (FMI 2.0's
  in fmus/, their FMI 3.0 twins in fmus/fmi3/);
- ``routes``: the FMI versions built, each with its pythonfmu through its fmukit
  adapter, and the entry module written into each FMU;
- ``packaging``: a slave script written with fmukit into a validated FMU of either
  version that carries exactly its model: what the script imports (``imports``), with
  its ``manifest``; the same bytes from the same sources (``reproducible``);
- ``manifest``: the build's side of an FMU's manifest (``fmukit.manifest`` reads it): who
  made it (``project_identity``) and the entry module this build writes;
- ``documentation``: what an FMU says of itself (its model description's author, version,
  copyright, license and generation tool; documentation/index.html); ``icon``: its model.png;
- ``trial``: an FMU instantiated once in a child process, here or away from the checkout;
- ``exit_fix``: pythonfmu 0.7.0's linux64 binary and pythonfmu3 0.3.4's x86_64-linux one,
  patched against their exit-time heap corruption;
- ``cbuild``: FMUs written in C (linux64, and win64 with mingw-w64);
- ``crosscheck``: the cross-check reference files (``python -m fmubuild.crosscheck``);
- ``cli``: the build command, ``python -m fmukit.build``.
"""
