# Runs at install time (cmake --install, CPack), so the paths follow the prefix of that install,
# whatever the build was configured with: `cmake --install build --prefix /usr` gives the same
# files as a build configured for /usr, and the unit's ExecStart names the icewatchd installed
# beside it. Needs ICEWATCH_SOURCE_DIR and ICEWATCH_BINARY_DIR (set by packaging/CMakeLists.txt).
#
#   prefix /usr (Debian)   unit /lib/systemd/system, rule /lib/udev/rules.d, sysusers
#                          /usr/lib/sysusers.d, configuration /etc/icewatch
#   any other prefix P     P/lib/systemd/system, P/lib/udev/rules.d, P/lib/sysusers.d, P/etc/icewatch
#                          (systemd, udev and sysusers all search /usr/local/lib as well)
if(CMAKE_INSTALL_PREFIX STREQUAL "/usr")
  set(lib_root "/lib")
  set(sysusers_dir "/usr/lib/sysusers.d")
  set(sysconf_dir "/etc")
else()
  set(lib_root "${CMAKE_INSTALL_PREFIX}/lib")
  set(sysusers_dir "${CMAKE_INSTALL_PREFIX}/lib/sysusers.d")
  set(sysconf_dir "${CMAKE_INSTALL_PREFIX}/etc")
endif()

# @ICEWATCHD@ and @ICEWATCH_CONFIG@ in the unit.
set(ICEWATCHD "${CMAKE_INSTALL_PREFIX}/bin/icewatchd")
set(ICEWATCH_CONFIG "${sysconf_dir}/icewatch/icewatch.json")
set(unit "${ICEWATCH_BINARY_DIR}/packaging/icewatchd.service")
configure_file("${ICEWATCH_SOURCE_DIR}/systemd/icewatchd.service.in" "${unit}" @ONLY)

file(INSTALL DESTINATION "${lib_root}/systemd/system" TYPE FILE FILES "${unit}")
file(INSTALL DESTINATION "${lib_root}/udev/rules.d" TYPE FILE
     FILES "${ICEWATCH_SOURCE_DIR}/systemd/60-icewatch-gpio.rules")
file(INSTALL DESTINATION "${sysusers_dir}" TYPE FILE RENAME icewatch.conf
     FILES "${ICEWATCH_SOURCE_DIR}/systemd/icewatch.sysusers")
file(INSTALL DESTINATION "${sysconf_dir}/icewatch" TYPE FILE FILES "${ICEWATCH_SOURCE_DIR}/config/icewatch.json")
