#pragma once

// Exit statuses a supervisor (systemd, a SCADA gateway script) can act on. The values are the
// BSD sysexits.h ones, so `RestartPreventExitStatus=78` keeps a bad configuration from looping.
namespace icewatch {

enum ExitCode : int {
    kExitOk = 0,
    kExitFailure = 1,       // the job ran and its answer is "no" (e.g. a measurement was refused)
    kExitUsage = 64,        // EX_USAGE: bad command-line arguments
    kExitDataErr = 65,      // EX_DATAERR: an input file exists but its content is wrong
    kExitNoInput = 66,      // EX_NOINPUT: an input file is missing or unreadable
    kExitUnavailable = 69,  // EX_UNAVAILABLE: a device or service is not there
    kExitSoftware = 70,     // EX_SOFTWARE: an internal error (a bug)
    kExitCantCreate = 73,   // EX_CANTCREAT: an output file cannot be created
    kExitIoErr = 74,        // EX_IOERR: an I/O error while reading or writing
    kExitTempFail = 75,     // EX_TEMPFAIL: try again later (camera offline, ...)
    kExitConfig = 78,       // EX_CONFIG: the configuration is invalid
};

}  // namespace icewatch
