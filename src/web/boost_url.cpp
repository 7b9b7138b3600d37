// Boost.URL's compiled part, built into finskit from Debian's libboost1.81-dev headers
// (the one translation unit that does so), so finsd needs no libboost-url at run time.
#include <boost/url/src.hpp>
