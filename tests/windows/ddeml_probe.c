/* ddeml_probe.exe: a native DDEML client, as Nova's Windows clients are (C, user32's DDEML, CF_TEXT).
 *
 * Built with mingw-w64 by tests/windows/test_installer.py and run under Wine against the installed
 * nfwserver.exe.  For each service named on the command line (e.g. NFW32 NFW_SERVER) it connects to
 * topic NFW_DATA (retrying until --wait seconds have passed, while the station starts), pokes "TUNE ON"
 * to item NFW_SERVER, requests the item once, then holds a hot advise loop until it has received COUNT
 * updates.  Every string received is printed on a line of its own:
 *     request SERVICE: TEXT
 *     advise SERVICE: TEXT
 * Exit status 0 when every step succeeded, 1 otherwise (the failing step and DdeGetLastError on stderr).
 * Usage: ddeml_probe.exe WAIT_SECONDS COUNT SERVICE...
 */
#include <windows.h>
#include <ddeml.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static DWORD instance;
static int advised;
static char current_service[64];

static void print_data(const char *what, HDDEDATA data)
{
    char text[512];
    DWORD n = DdeGetData(data, (LPBYTE)text, sizeof text - 1, 0);
    text[n < sizeof text ? n : sizeof text - 1] = 0;
    printf("%s %s: %s\n", what, current_service, text);
    fflush(stdout);
}

static HDDEDATA CALLBACK callback(UINT type, UINT format, HCONV conv, HSZ topic, HSZ item, HDDEDATA data,
                                  ULONG_PTR d1, ULONG_PTR d2)
{
    (void)format; (void)conv; (void)topic; (void)item; (void)d1; (void)d2;
    if (type == XTYP_ADVDATA) {
        print_data("advise", data);
        advised++;
        return (HDDEDATA)DDE_FACK;
    }
    return NULL;
}

static int fail(const char *step)
{
    fprintf(stderr, "ddeml_probe: %s failed on %s (DdeGetLastError 0x%x)\n", step, current_service,
            DdeGetLastError(instance));
    return 1;
}

static void pump(DWORD ms)
{
    ULONGLONG until = GetTickCount64() + ms;
    MSG msg;
    do {
        while (PeekMessageA(&msg, NULL, 0, 0, PM_REMOVE)) {
            TranslateMessage(&msg);
            DispatchMessageA(&msg);
        }
        MsgWaitForMultipleObjects(0, NULL, FALSE, 20, QS_ALLINPUT);
    } while (GetTickCount64() < until);
}

static int probe(const char *service, double wait_s, int count)
{
    strncpy(current_service, service, sizeof current_service - 1);
    HSZ hs = DdeCreateStringHandleA(instance, service, CP_WINANSI);
    HSZ ht = DdeCreateStringHandleA(instance, "NFW_DATA", CP_WINANSI);
    HSZ hi = DdeCreateStringHandleA(instance, "NFW_SERVER", CP_WINANSI);
    ULONGLONG give_up = GetTickCount64() + (ULONGLONG)(wait_s * 1000.0);
    HCONV conv;
    while ((conv = DdeConnect(instance, hs, ht, NULL)) == NULL) {
        if (GetTickCount64() > give_up)
            return fail("DdeConnect");
        pump(200);
    }
    DWORD result = 0;
    static const char tune[] = "TUNE ON";
    if (!DdeClientTransaction((LPBYTE)tune, sizeof tune, conv, hi, CF_TEXT, XTYP_POKE, 10000, &result))
        return fail("poke TUNE ON");
    /* The first tick after TUNE ON may be a moment away: request until a string arrives. */
    for (;;) {
        HDDEDATA data = DdeClientTransaction(NULL, 0, conv, hi, CF_TEXT, XTYP_REQUEST, 10000, &result);
        if (data == NULL)
            return fail("request");
        DWORD size = DdeGetData(data, NULL, 0, 0);
        if (size > 1) {
            print_data("request", data);
            DdeFreeDataHandle(data);
            break;
        }
        DdeFreeDataHandle(data);
        if (GetTickCount64() > give_up)
            return fail("request (only empty strings)");
        pump(100);
    }
    advised = 0;
    if (!DdeClientTransaction(NULL, 0, conv, hi, CF_TEXT, XTYP_ADVSTART, 10000, &result))
        return fail("advise start");
    ULONGLONG advise_until = GetTickCount64() + 30000;
    while (advised < count && GetTickCount64() < advise_until)
        pump(50);
    if (advised < count)
        return fail("advise loop (too few updates)");
    DdeClientTransaction(NULL, 0, conv, hi, CF_TEXT, XTYP_ADVSTOP, 10000, &result);
    DdeDisconnect(conv);
    DdeFreeStringHandle(instance, hs);
    DdeFreeStringHandle(instance, ht);
    DdeFreeStringHandle(instance, hi);
    return 0;
}

int main(int argc, char **argv)
{
    if (argc < 4) {
        fprintf(stderr, "usage: ddeml_probe WAIT_SECONDS COUNT SERVICE...\n");
        return 2;
    }
    if (DdeInitializeA(&instance, callback, APPCMD_CLIENTONLY, 0) != DMLERR_NO_ERROR) {
        fprintf(stderr, "ddeml_probe: DdeInitialize failed\n");
        return 1;
    }
    int status = 0;
    for (int i = 3; i < argc && status == 0; i++)
        status = probe(argv[i], atof(argv[1]), atoi(argv[2]));
    DdeUninitialize(instance);
    return status;
}
