/* lnk_probe.exe: what a Windows shortcut (.lnk) starts, read through the shell's own IShellLinkW.
 *
 * Built with mingw-w64 by tests/windows/test_installer.py and run under Wine on the Start-menu entries
 * the installer made.  For each .lnk named on the command line it prints one line,
 *     TARGET|ARGUMENTS|WORKING_FOLDER
 * and exits 0, or 1 when a shortcut cannot be read.  Usage: lnk_probe.exe LINK...
 */
#define COBJMACROS
#include <windows.h>
#include <shlobj.h>
#include <shobjidl.h>
#include <stdio.h>

int wmain(int argc, wchar_t **argv)
{
    if (FAILED(CoInitializeEx(NULL, COINIT_APARTMENTTHREADED)))
        return 1;
    int status = 0;
    for (int i = 1; i < argc; i++) {
        IShellLinkW *link = NULL;
        IPersistFile *file = NULL;
        wchar_t target[MAX_PATH] = L"", args[1024] = L"", folder[MAX_PATH] = L"";
        if (FAILED(CoCreateInstance(&CLSID_ShellLink, NULL, CLSCTX_INPROC_SERVER, &IID_IShellLinkW,
                                    (void **)&link))
            || FAILED(IShellLinkW_QueryInterface(link, &IID_IPersistFile, (void **)&file))
            || FAILED(IPersistFile_Load(file, argv[i], STGM_READ))
            || FAILED(IShellLinkW_GetPath(link, target, MAX_PATH, NULL, SLGP_RAWPATH))
            || FAILED(IShellLinkW_GetArguments(link, args, 1024))
            || FAILED(IShellLinkW_GetWorkingDirectory(link, folder, MAX_PATH))) {
            fwprintf(stderr, L"lnk_probe: cannot read %ls\n", argv[i]);
            status = 1;
        } else {
            wprintf(L"%ls|%ls|%ls\n", target, args, folder);
        }
        if (file != NULL)
            IPersistFile_Release(file);
        if (link != NULL)
            IShellLinkW_Release(link);
    }
    fflush(stdout);
    CoUninitialize();
    return status;
}
