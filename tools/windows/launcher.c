/* nfwserver.exe / nfwserverw.exe: the installed program's entry points.
 *
 * Each loads the embeddable CPython that sits beside it (python312.dll, its ._pth file naming the
 * standard library zip and Lib\site-packages) and runs `python -I -m nfwserver ARGS...` inside this
 * process, so the station shows as nfwserver.exe in the Task Manager and a console's Ctrl+C reaches
 * Python directly.  Python's byte-code cache goes to the user's %LOCALAPPDATA%\nfwserver\Cache\pycache
 * (-X pycache_prefix), never into the program's folder, which holds exactly what the installer put there
 * (without a known LocalAppData folder, -B: no cache at all).  nfwserver.exe is a console program (the station's console, every command);
 * nfwserverw.exe is built with NFW_WINDOWLESS as a GUI-subsystem program with no console window (start at
 * logon, the Start-menu entries that need no terminal).  Built by tools/windows/build with mingw-w64.
 */
#include <windows.h>
#include <shellapi.h>
#include <shlobj.h>
#include <stdio.h>
#include <stdlib.h>
#include <wchar.h>

typedef int(__cdecl *py_main_fn)(int, wchar_t **);

static int fail(const wchar_t *what, const wchar_t *detail)
{
    wchar_t text[2048];
    _snwprintf(text, sizeof text / sizeof text[0] - 1, L"nfwserver: %ls%ls (reinstall nfwserver to repair)", what,
               detail);
    text[sizeof text / sizeof text[0] - 1] = 0;
#ifdef NFW_WINDOWLESS
    MessageBoxW(NULL, text, L"nfwserver", MB_OK | MB_ICONERROR);
#else
    fwprintf(stderr, L"%ls\n", text);
#endif
    return 3;
}

/* FOLDERID_LocalAppData, {F1B32785-6FBA-4FCF-9D55-7B8E7F157091} (KnownFolders.h), written here: mingw-w64's
 * libuuid would link 40 KB of every other GUID into each launcher. */
static const GUID local_app_data = {0xF1B32785, 0x6FBA, 0x4FCF, {0x9D, 0x55, 0x7B, 0x8E, 0x7F, 0x15, 0x70, 0x91}};

/* "pycache_prefix=<LocalAppData>\nfwserver\Cache\pycache" in `out`, or L"" when the folder is unknown. */
static void pycache_option(wchar_t *out, size_t size)
{
    PWSTR local = NULL;
    out[0] = 0;
    if (SUCCEEDED(SHGetKnownFolderPath(&local_app_data, 0, NULL, &local)) && local != NULL)
        _snwprintf(out, size - 1, L"pycache_prefix=%ls\\nfwserver\\Cache\\pycache", local);
    out[size - 1] = 0;
    CoTaskMemFree(local);
}

static int launch(void)
{
    static wchar_t pycache[32768 + 64];
    pycache_option(pycache, sizeof pycache / sizeof pycache[0]);
    const wchar_t *fixed[] = {L"-I", L"-X", pycache, L"-m", L"nfwserver"};
    if (pycache[0] == 0) {
        fixed[1] = L"-I";
        fixed[2] = L"-B";
    }
    const int nfixed = (int)(sizeof fixed / sizeof fixed[0]);
    wchar_t dll[32768];
    DWORD n = GetModuleFileNameW(NULL, dll, (DWORD)(sizeof dll / sizeof dll[0]));
    if (n == 0 || n >= sizeof dll / sizeof dll[0] - 32)
        return fail(L"cannot find where this program is installed", L"");
    wchar_t *slash = wcsrchr(dll, L'\\');
    if (slash == NULL)
        return fail(L"cannot find where this program is installed", L"");
    wcscpy(slash + 1, L"python312.dll");
    HMODULE python = LoadLibraryExW(dll, NULL, LOAD_WITH_ALTERED_SEARCH_PATH);
    if (python == NULL)
        return fail(L"cannot load ", dll);
    py_main_fn py_main = (py_main_fn)(void (*)(void))GetProcAddress(python, "Py_Main");
    if (py_main == NULL)
        return fail(L"no Py_Main in ", dll);

    int argc = 0;
    wchar_t **argv = CommandLineToArgvW(GetCommandLineW(), &argc);
    if (argv == NULL || argc < 1)
        return fail(L"cannot read the command line", L"");
    wchar_t **args = calloc((size_t)argc + (size_t)nfixed + 1, sizeof *args);
    if (args == NULL)
        return fail(L"out of memory", L"");
    args[0] = argv[0];
    for (int i = 0; i < nfixed; i++)
        args[1 + i] = (wchar_t *)fixed[i];
    for (int i = 1; i < argc; i++)
        args[nfixed + i] = argv[i];
    int status = py_main(argc + nfixed, args);
#ifndef NFW_WINDOWLESS
    /* Started from the Start menu or Explorer, this program owns its console window, which closes when it
     * exits: a failure ("a station is already running") would flash by unread.  Then wait for Enter. */
    DWORD owners[2];
    DWORD mode;
    if (status != 0 && GetConsoleProcessList(owners, 2) == 1
        && GetConsoleMode(GetStdHandle(STD_INPUT_HANDLE), &mode)) {
        fwprintf(stderr, L"\nPress Enter to close this window.\n");
        fflush(stderr);
        (void)getwchar();
    }
#endif
    return status;
}

#ifdef NFW_WINDOWLESS
int WINAPI wWinMain(HINSTANCE instance, HINSTANCE previous, PWSTR command_line, int show)
{
    (void)instance;
    (void)previous;
    (void)command_line;
    (void)show;
    return launch();
}
#else
int wmain(void)
{
    return launch();
}
#endif
