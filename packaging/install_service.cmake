# Runs at install time, once the prefix is known, so that the unit names the daemon and the
# config where they really are: /usr/bin/covtrackd and /etc/covtrack for a Debian package
# (prefix /usr), <prefix>/bin and <prefix>/etc/covtrack for any other prefix.
# Set before it (install(CODE)): COVTRACK_SERVICE_TEMPLATE, COVTRACK_DEFAULT_CONFIG,
# COVTRACK_BINDIR, COVTRACK_STAGING_DIR.
if(CMAKE_INSTALL_PREFIX STREQUAL "/usr")
  set(etc_dir /etc/covtrack)
else()
  set(etc_dir ${CMAKE_INSTALL_PREFIX}/etc/covtrack)
endif()
set(COVTRACKD ${CMAKE_INSTALL_PREFIX}/${COVTRACK_BINDIR}/covtrackd)
set(COVTRACK_CONFIG ${etc_dir}/covtrackd.toml)
configure_file(${COVTRACK_SERVICE_TEMPLATE} ${COVTRACK_STAGING_DIR}/covtrackd.service @ONLY)
file(INSTALL ${COVTRACK_STAGING_DIR}/covtrackd.service DESTINATION ${CMAKE_INSTALL_PREFIX}/lib/systemd/system)
# An edited config is kept: a later install does not overwrite it.
if(NOT EXISTS "$ENV{DESTDIR}${COVTRACK_CONFIG}")
  file(INSTALL ${COVTRACK_DEFAULT_CONFIG} DESTINATION ${etc_dir} RENAME covtrackd.toml)
endif()
