; nfwserver's Windows installer (NSIS 3, built on Linux by tools/windows/build; docs/WINDOWS.md).
;
; A per-user install: no administrator rights, files in %LOCALAPPDATA%\Programs\nfwserver (or /D=), the
; uninstall entry under HKCU, Start-menu entries for this user, and optionally start at logon through the
; user's Run key (never a Windows service: services live in session 0, where the desktop's DDE clients
; cannot reach the station).  /S installs silently; /LOGON (or /LOGON=0) switches start at logon on (off)
; for a silent install.  An install over an earlier one stops its running station cleanly
; (`nfwserver stop`), replaces the program, keeps the user's configuration, state, logs and element store
; (they live in %LOCALAPPDATA%\nfwserver, never in the program's folder); one installed in another folder
; is removed first.  An upgrade leaves exactly the new program in its folder: the older program is removed by
; its own uninstaller (which knows its files), and anything else at the folder's top (a user's file) is moved
; to %LOCALAPPDATA%\nfwserver\Left in the program folder.  With start at logon the station is started at the
; end, as the next logon would.  Exit status: 0 done, 2 a folder holding someone else's files was refused, 3 a
; running station did not stop.
;
; Defined by the build: VERSION, VERSION_QUAD, STAGE (the staged program folder), OUTFILE; included: size.nsh,
; files.nsh, uninstall.nsh, known.nsh (tools/windows/stage.py).

Target amd64-unicode  ; the program is win_amd64, and a 64-bit setup also runs on a 64-bit-only Wine
ManifestDPIAware true
RequestExecutionLevel user
SetCompressor /SOLID /FINAL lzma
SetCompressorDictSize 64
SetDateSave on
CRCCheck on

!include "MUI2.nsh"
!include "FileFunc.nsh"
!include "LogicLib.nsh"
!include "size.nsh"

!define PRODUCT "nfwserver"
!define PUBLISHER "nfwserver developers"
!define UNINST_KEY "Software\Microsoft\Windows\CurrentVersion\Uninstall\${PRODUCT}"
!define RUN_KEY "Software\Microsoft\Windows\CurrentVersion\Run"
!define MENU "$SMPROGRAMS\${PRODUCT}"
!define KEPT "$LOCALAPPDATA\${PRODUCT}\Left in the program folder"

Name "${PRODUCT} ${VERSION}"
OutFile "${OUTFILE}"
InstallDir "$LOCALAPPDATA\Programs\${PRODUCT}"
InstallDirRegKey HKCU "${UNINST_KEY}" "InstallLocation"
BrandingText "${PRODUCT} ${VERSION}"
ShowInstDetails show
ShowUninstDetails show

VIProductVersion "${VERSION_QUAD}"
VIAddVersionKey "ProductName" "${PRODUCT}"
VIAddVersionKey "ProductVersion" "${VERSION}"
VIAddVersionKey "FileVersion" "${VERSION}"
VIAddVersionKey "FileDescription" "${PRODUCT} ${VERSION} setup"
VIAddVersionKey "CompanyName" "${PUBLISHER}"
VIAddVersionKey "LegalCopyright" "MIT licence"

!define MUI_ICON "${STAGE}\nfwserver.ico"
!define MUI_UNICON "${STAGE}\nfwserver.ico"
!define MUI_ABORTWARNING
!define MUI_COMPONENTSPAGE_NODESC
!define MUI_FINISHPAGE_RUN "$INSTDIR\nfwserver.exe"
!define MUI_FINISHPAGE_RUN_PARAMETERS "run"
!define MUI_FINISHPAGE_RUN_TEXT "Start the station now (its console in a terminal window)"
!define MUI_FINISHPAGE_RUN_NOTCHECKED
!define MUI_FINISHPAGE_SHOWREADME ""
!define MUI_FINISHPAGE_SHOWREADME_TEXT "Open the configuration (your station's location, rotor, radio)"
!define MUI_FINISHPAGE_SHOWREADME_FUNCTION OpenConfiguration
!define MUI_FINISHPAGE_SHOWREADME_NOTCHECKED
!insertmacro MUI_PAGE_WELCOME
!insertmacro MUI_PAGE_COMPONENTS
!insertmacro MUI_PAGE_DIRECTORY
!insertmacro MUI_PAGE_INSTFILES
!insertmacro MUI_PAGE_FINISH
!insertmacro MUI_UNPAGE_CONFIRM
!insertmacro MUI_UNPAGE_INSTFILES
!insertmacro MUI_LANGUAGE "English"

; StopStation: ask a running station of this user to stop (`nfwserver stop`, which waits until its process has
; ended, so that its files can be replaced).  A station that has not stopped within a minute ends the setup or
; the uninstall (exit 3): its files are in use, and replacing or removing some of them would leave a program of
; two versions, or half of one.  Nothing happens when no program is installed at $INSTDIR yet.
!macro StopStation
  ${If} ${FileExists} "$INSTDIR\nfwserver.exe"
    DetailPrint "Stopping a running station (nfwserver stop)..."
    nsExec::ExecToLog '"$INSTDIR\nfwserver.exe" stop --timeout 60'
    Pop $0
    ${If} $0 == "3"
      MessageBox MB_OK|MB_ICONSTOP "The running station did not stop within a minute, so its files cannot be replaced.$\r$\nStop it (its console, or Start > nfwserver > Stop the station), then run this again." /SD IDOK
      SetErrorLevel 3
      Quit
    ${EndIf}
  ${EndIf}
!macroend

; NotOurFolder: "1" in $R1 when $INSTDIR holds files and is not an nfwserver install (a folder of someone else's,
; whose Lib folder an upgrade or the uninstaller would remove); "0" for a new or empty folder, the registered
; install, or one holding this installer's uninstall.exe and python312._pth (even if nfwserver.exe itself went
; missing: reinstalling repairs it).
!macro NotOurFolder
  StrCpy $R1 "0"
  ${DirState} "$INSTDIR" $R0
  ReadRegStr $R2 HKCU "${UNINST_KEY}" "InstallLocation"
  ${If} $R0 == 1
  ${AndIf} $R2 != $INSTDIR
    ${IfNot} ${FileExists} "$INSTDIR\uninstall.exe"
    ${OrIfNot} ${FileExists} "$INSTDIR\python312._pth"
      StrCpy $R1 "1"
    ${EndIf}
  ${EndIf}
!macroend

; KeepForeignFiles: every top-level entry of $INSTDIR that is not the program's (known.nsh) is moved to ${KEPT}
; (copied, then removed once the copy succeeded): after an upgrade the folder holds the new program only, and
; nothing of the user's is lost.
!macro KeepForeignFiles
  FindFirst $R7 $R9 "$INSTDIR\*"
  ${DoWhile} $R9 != ""
    ${If} $R9 != "."
    ${AndIf} $R9 != ".."
      !include "known.nsh"
      ${If} $R8 == "0"
        DetailPrint "Moving $R9, which is not nfwserver's, to ${KEPT}"
        CreateDirectory "${KEPT}"
        ClearErrors
        CopyFiles /SILENT "$INSTDIR\$R9" "${KEPT}"
        ${IfNot} ${Errors}
          RMDir /r "$INSTDIR\$R9"
          Delete "$INSTDIR\$R9"
        ${EndIf}
      ${EndIf}
    ${EndIf}
    FindNext $R7 $R9
  ${Loop}
  FindClose $R7
!macroend

Function .onVerifyInstDir
  !insertmacro NotOurFolder
  ${If} $R1 == "1"
    Abort  ; the Next button stays off: choose an empty folder or a new one
  ${EndIf}
FunctionEnd

Section "nfwserver (required)" SecProgram
  SectionIn RO
  SetShellVarContext current
  !insertmacro NotOurFolder
  ${If} $R1 == "1"
    MessageBox MB_OK|MB_ICONSTOP "$INSTDIR holds other files: nfwserver installs only into an empty folder, a new one or its own." /SD IDOK
    SetErrorLevel 2
    Quit
  ${EndIf}
  ; Installed elsewhere before: that install is removed first (its uninstaller stops its station), so that
  ; one program and one Apps & features entry remain.
  ReadRegStr $R2 HKCU "${UNINST_KEY}" "InstallLocation"
  ${If} $R2 != ""
  ${AndIf} $R2 != $INSTDIR
  ${AndIf} ${FileExists} "$R2\uninstall.exe"
    DetailPrint "Removing the earlier install in $R2 (nfwserver moves to $INSTDIR)"
    ExecWait '"$R2\uninstall.exe" /S _?=$R2' $0
    ${If} $0 != 0
      MessageBox MB_OK|MB_ICONSTOP "The earlier install in $R2 could not be removed (its station did not stop).$\r$\nStop it, then run this again." /SD IDOK
      SetErrorLevel 3
      Quit
    ${EndIf}
    Delete "$R2\uninstall.exe"
    RMDir "$R2"
  ${EndIf}
  !insertmacro StopStation
  ; An upgrade replaces the whole program: what an older version had and this one does not must not stay
  ; importable.  The older version's uninstaller removes its files (its start-at-logon and Apps & features
  ; entries are written again below); what is left and is not this program's is the user's (KeepForeignFiles).
  ${If} ${FileExists} "$INSTDIR\uninstall.exe"
    DetailPrint "Removing the installed version before installing ${VERSION}"
    ExecWait '"$INSTDIR\uninstall.exe" /S _?=$INSTDIR' $0
    ${If} $0 != 0
      MessageBox MB_OK|MB_ICONSTOP "The installed version could not be removed (its station did not stop).$\r$\nStop it, then run this again." /SD IDOK
      SetErrorLevel 3
      Quit
    ${EndIf}
  ${EndIf}
  !insertmacro KeepForeignFiles
  !include "uninstall.nsh"
  !include "files.nsh"
  SetOutPath "$INSTDIR"
  WriteUninstaller "$INSTDIR\uninstall.exe"

  WriteRegStr HKCU "${UNINST_KEY}" "DisplayName" "${PRODUCT} ${VERSION}"
  WriteRegStr HKCU "${UNINST_KEY}" "DisplayVersion" "${VERSION}"
  WriteRegStr HKCU "${UNINST_KEY}" "Publisher" "${PUBLISHER}"
  WriteRegStr HKCU "${UNINST_KEY}" "DisplayIcon" '"$INSTDIR\nfwserver.exe",0'
  WriteRegStr HKCU "${UNINST_KEY}" "InstallLocation" "$INSTDIR"
  WriteRegStr HKCU "${UNINST_KEY}" "UninstallString" '"$INSTDIR\uninstall.exe"'
  WriteRegStr HKCU "${UNINST_KEY}" "QuietUninstallString" '"$INSTDIR\uninstall.exe" /S'
  WriteRegDWORD HKCU "${UNINST_KEY}" "EstimatedSize" ${ESTIMATED_SIZE_KB}
  WriteRegDWORD HKCU "${UNINST_KEY}" "NoModify" 1
  WriteRegDWORD HKCU "${UNINST_KEY}" "NoRepair" 1

  ; Start menu: working folder the user's profile (where a relative path given to a command is looked for).
  SetOutPath "$PROFILE"
  RMDir /r "${MENU}"
  CreateDirectory "${MENU}"
  CreateShortCut "${MENU}\nfwserver station.lnk" "$INSTDIR\nfwserver.exe" "run" "$INSTDIR\nfwserver.exe" 0 \
    SW_SHOWNORMAL "" "The station with its console (Ctrl+Q stops it)"
  CreateShortCut "${MENU}\nfwserver dashboard.lnk" "$INSTDIR\nfwserverw.exe" "dashboard" \
    "$INSTDIR\nfwserver.exe" 0 SW_SHOWNORMAL "" "The running station's web page in your browser"
  CreateShortCut "${MENU}\nfwserver configuration.lnk" "$INSTDIR\nfwserverw.exe" "config edit" \
    "$INSTDIR\nfwserver.exe" 0 SW_SHOWNORMAL "" "Your configuration file in the editor (created when missing)"
  CreateShortCut "${MENU}\Stop the station.lnk" "$INSTDIR\nfwserverw.exe" "stop" "$INSTDIR\nfwserver.exe" 0 \
    SW_SHOWNORMAL "" "Ask the running station to stop cleanly"
  SetOutPath "$INSTDIR"

  ; A first install gets a configuration that serves the dashboard on 127.0.0.1; an existing one is kept.
  nsExec::ExecToLog '"$INSTDIR\nfwserver.exe" config init --web --keep'
  Pop $0
SectionEnd

Section /o "Start the station at logon (no window; stop it from the Start menu)" SecLogon
  WriteRegStr HKCU "${RUN_KEY}" "${PRODUCT}" '"$INSTDIR\nfwserverw.exe" run --headless'
SectionEnd

Section "-after"
  ${IfNot} ${SectionIsSelected} ${SecLogon}
    DeleteRegValue HKCU "${RUN_KEY}" "${PRODUCT}"
  ${EndIf}
  ; With start at logon the station is started now too, as the next logon would (after an upgrade: again);
  ; a station that was run from a terminal is left for its user to start again.
  ${If} ${SectionIsSelected} ${SecLogon}
    DetailPrint "Starting the station (it starts at logon)"
    Exec '"$INSTDIR\nfwserverw.exe" run --headless'
  ${EndIf}
SectionEnd

Function .onInit
  SetShellVarContext current
  ; Start at logon: kept as it was on an upgrade; /LOGON or /LOGON=1 switches it on, /LOGON=0 off.
  ReadRegStr $0 HKCU "${RUN_KEY}" "${PRODUCT}"
  ${If} $0 != ""
    !insertmacro SelectSection ${SecLogon}
  ${EndIf}
  ${GetParameters} $1
  ClearErrors
  ${GetOptions} $1 "/LOGON" $2
  ${IfNot} ${Errors}
    ${If} $2 == "=0"
      !insertmacro UnselectSection ${SecLogon}
    ${Else}
      !insertmacro SelectSection ${SecLogon}
    ${EndIf}
  ${EndIf}
FunctionEnd

Function OpenConfiguration
  Exec '"$INSTDIR\nfwserverw.exe" config edit'
FunctionEnd

Section "Uninstall"
  SetShellVarContext current
  !insertmacro StopStation
  DeleteRegValue HKCU "${RUN_KEY}" "${PRODUCT}"
  RMDir /r "${MENU}"
  !include "uninstall.nsh"
  Delete "$INSTDIR\uninstall.exe"
  RMDir "$INSTDIR"
  DeleteRegKey HKCU "${UNINST_KEY}"
  DetailPrint "Kept your configuration, saved state, logs and element store in $LOCALAPPDATA\${PRODUCT}"
  DetailPrint "(delete that folder too to remove every trace of ${PRODUCT})."
  IfSilent +2
    MessageBox MB_OK|MB_ICONINFORMATION "${PRODUCT} is removed.$\r$\n$\r$\nYour configuration, saved state, logs and element store are kept in $LOCALAPPDATA\${PRODUCT}; delete that folder to remove them too."
SectionEnd
