#include <sys/mman.h>
#include <chrono>
#include <cstdio>
#include <cstring>
int main(){ for (int rep=0; rep<3; ++rep) { size_t n = 20u<<20; char* p=(char*)mmap(nullptr,n,PROT_READ|PROT_WRITE,MAP_PRIVATE|MAP_ANONYMOUS,-1,0);
 auto t=std::chrono::steady_clock::now(); for(size_t i=0;i<n;i+=4096) p[i]=1; double s=std::chrono::duration<double>(std::chrono::steady_clock::now()-t).count();
 printf("4K: %.2f us/page, total %.1f ms\n", s*1e6/(n/4096), s*1e3); munmap(p,n);
 p=(char*)mmap(nullptr,n+(2<<20),PROT_READ|PROT_WRITE,MAP_PRIVATE|MAP_ANONYMOUS,-1,0); char* a=(char*)(((size_t)p+(2<<20)-1)&~size_t((2<<20)-1)); madvise(a,n,MADV_HUGEPAGE);
 t=std::chrono::steady_clock::now(); for(size_t i=0;i<n;i+=4096) a[i]=1; s=std::chrono::duration<double>(std::chrono::steady_clock::now()-t).count();
 printf("THP: total %.1f ms\n", s*1e3); munmap(p,n+(2<<20)); }}
