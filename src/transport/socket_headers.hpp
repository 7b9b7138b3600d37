#pragma once
// The BSD socket types and helpers (sockaddr_storage, sockaddr_in, socklen_t, inet_pton,
// inet_ntop, htons...) on Linux and on Windows, where Winsock 2 has them
// (docs/windows.md).
#ifdef _WIN32
// Winsock's headers need their order: winsock2.h first.
#include <winsock2.h>

#include <ws2tcpip.h>
#else
#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#endif
